#pragma once
// Options of the small generated scenes the tests carve (header-only: the tests that use it link
// raycarve_samples).

#include "samples/synthetic_scene.h"

namespace raycarve {
namespace testing {

// `views` cameras of `width` x `height`, `surface_samples` candidate sparse points (0: none), and
// a patchwork sky or a uniform backdrop.
inline SyntheticSceneOptions SceneOptions(int views,
                                          int width,
                                          int height,
                                          bool uniform_backdrop = false,
                                          int surface_samples = 0) {
  SyntheticSceneOptions options;
  options.num_views = views;
  options.width = width;
  options.height = height;
  options.num_surface_samples = surface_samples;
  options.backdrop = uniform_backdrop ? Backdrop::kUniform : Backdrop::kPatchwork;
  return options;
}

}  // namespace testing
}  // namespace raycarve
