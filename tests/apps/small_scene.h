// The small scene of the apps tests: three segments, the end held in y and pushed along x over a
// short Fx path, continuation only, no plots: a run takes milliseconds.
#pragma once

#include <string>

namespace buckle::test {

/// The scene's text with the given branch-switching depth.
inline std::string smallScene(int branchSwitching) {
  return R"({
  "description": "small test chain",
  "chain": {"segments": 3, "a": 0.5, "b": 1.0, "k": 1.0, "L0": 2.25},
  "end": {"x": {"load": 0.0}, "y": {"held": 0.0}, "phi": "free"},
  "path": {"parameter": "Fx", "from": 0.0, "to": -1.0},
  "analyses": {"continuation": {"branch_switching": )" +
         std::to_string(branchSwitching) + R"(}},
  "plots": []
})";
}

}  // namespace buckle::test
