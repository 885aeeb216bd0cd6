#include "option_names.hpp"

#include <utility>
#include <vector>

#include "shadowfilter/parameters.hpp"
#include "shadowfilter/soft.hpp"

namespace sf::cli {

// Field (as the library's messages name it) -> the flag that sets it: the declared parameters'
// (built at each message: a method registered after the first message brings its flags too),
// SoftOptions' and the input decoders'.
std::string cli_message(std::string s) {
  std::vector<std::pair<std::string, std::string>> t = option_flags();
  t.insert(t.end(), soft_option_flags().begin(), soft_option_flags().end());
  t.insert(t.end(), {
                        {"DepthDecoding::near_plane", "--near"},
                        {"DepthDecoding::far_plane", "--far"},
                        {"DepthDecoding::beyond_far_is_empty", "--beyond-far far"},
                        {"CameraDepth::kind", "--camera-depth-kind"},
                        {"CameraReceiverOptions::map_width and map_height", "--map-size"},
                    });
  return rename_fields(std::move(s), std::move(t));
}

}  // namespace sf::cli
