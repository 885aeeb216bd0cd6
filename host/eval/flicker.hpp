#pragma once
// Flicker of a frame sequence (evaluate --frames): scene directories that are consecutive frames
// seen from one still camera (a light moving, say), so that a receiver is one world point in
// every frame. Per configuration, the flicker of a frame pair is mean |e_t - e_(t-1)| over the
// receivers both frames count (Scene::traced), e = v - reference: the soft reference when every
// frame has one, else the hard one. A method that tracked the reference exactly would not
// flicker, whatever the light does; what changes otherwise is the method's.
#include <map>
#include <string>
#include <vector>

#include "evaluate.hpp"

namespace sf::eval {

// One configuration over the sequence: its error against the sequence's reference (mean over
// frames of the per-frame RMSE), its flicker (mean over frame pairs) and its median time.
struct FlickerRow {
  std::string method, label;
  int frames = 0;
  double rmse = 0, flicker = -1, time_ms = 0;
};

class FlickerTracker {
 public:
  // Checks the next frame against the first (the first picks the reference): InputError when its
  // receivers differ in size from the first frame's, when both have a view.exr whose world
  // positions differ (the camera moved), or when it lacks the reference the first chose. Every
  // frame may be checked up front, before any row exists.
  void check_frame(const Scene& scene);
  // Adds the next frame's scene and its rows (with their visibility images), checking the frame
  // first unless check_frame already did.
  void add_frame(const Scene& scene, const std::vector<Row>& rows);
  std::vector<FlickerRow> rows() const;  // in the first frame's order of configurations
  const char* reference() const { return soft_ ? "soft" : "hard"; }

 private:
  struct Track {
    FlickerRow row;
    std::vector<float> last_error;  // NaN where the last frame did not count the receiver
    int last_frame = -1;            // the frame last_error belongs to
    double rmse_sum = 0, flicker_sum = 0;
    int pairs = 0;
    std::vector<double> times;
  };
  int frames_ = 0;   // frames added
  int checked_ = 0;  // frames checked
  bool soft_ = false;
  std::string first_dir_;
  int width_ = 0, height_ = 0;
  std::vector<float> view_;  // the first frame's world positions (x y z per receiver), if any
  std::vector<std::string> order_;
  std::map<std::string, Track> tracks_;  // key: method + "|" + label
};

// results_frames.csv (one line per configuration) and its Markdown table.
void write_flicker_csv(const std::string& path, const std::vector<FlickerRow>& rows, const std::string& reference);
std::string flicker_markdown(const std::vector<FlickerRow>& rows, const std::string& reference);
// flicker.png: each configuration at (flicker, RMSE) in its method's colour, the front of
// configurations no other beats on both marked and labelled (8-bit RGB, written atomically).
void write_flicker_png(const std::string& path, const std::vector<FlickerRow>& rows, const std::string& reference,
                       int frames);

}  // namespace sf::eval
