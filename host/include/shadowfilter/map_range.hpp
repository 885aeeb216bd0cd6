#pragma once
// The depth range of a shadow map: its least and largest finite depth. A basis of exponentials
// spans exp(c (max - min)) over the map, and where a lookup's precision depends on that span
// (the summed-area table: MethodDesc::sat_limit) the pipeline checks the range before it runs.

namespace sf {

struct MapRange {
  float min = 0.0f, max = 1.0f;
  // max - min; 0 for a map without finite depths (min > max), which no limit refuses.
  float span() const { return max > min ? max - min : 0.0f; }
};

}  // namespace sf
