#pragma once
// Layered shadow maps on disk (cascades.hpp): one EXR per layer and the camera view they are read
// from. A layer file is a depth map (one channel Z, linear depth of its layer, 1 = nothing hit)
// whose header carries its place in the set:
//   shadowfilter:world_to_map  16 numbers, the row-major matrix of LayerTransform
//   shadowfilter:split         "near far", the view depths the layer serves
//   shadowfilter:layer         "k K", its index and the set's layer count
//   shadowfilter:blend         the set's blend band (CascadeSet::blend)
// The view file (view.exr) holds the channels of ViewReceivers by name: P.x P.y P.z depth
// dPdx.x dPdx.y dPdx.z dPdy.x dPdy.y dPdy.z [ndl], float (ndl may be half).
#include <map>
#include <string>
#include <vector>

#include "shadowfilter/cascades.hpp"
#include "shadowfilter/host_image.hpp"

namespace sf::io {

struct LayeredMaps {
  CascadeSet set;
  std::vector<HostImage> maps;  // one depth map per layer, linear [0, 1]
};

// The layer files of --cascades: a directory (its cascade_0.exr, cascade_1.exr, ... in order, until
// one is missing) or a comma-separated list of files. InputError when it names none.
std::vector<std::string> cascade_files(const std::string& dir_or_list);

// Reads and validates a cascade set (sf::validate, plus: every layer of one size, a header naming
// its index k of the count given, a finite depth map). InputError naming the file otherwise.
LayeredMaps load_cascade_set(const std::vector<std::string>& paths);

// The header attributes of layer k of a set (what load_cascade_set reads back exactly).
std::map<std::string, std::string> cascade_layer_attributes(const CascadeSet& set, int k);

// Channel names of a view file, in the order the scene generator writes them.
const std::vector<std::string>& view_channel_names();

// Reads a view file (channels by name, see above). Pixels with any non-finite position, depth or
// offset are background (all NaN). InputError for missing channels or non-float data.
ViewReceivers load_view_receivers(const std::string& path);

}  // namespace sf::io
