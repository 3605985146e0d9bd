// scenes/moment_set.hpp — the moments of a scene at its initial poses, without ODE: what
// the magnetics-only experiments (Figs. 8–10, speed against accuracy) run on.
#pragma once

#include "engine/scene_desc.hpp"
#include "magnetics/moments.hpp"

namespace magsim::scenes {

/// World positions = body pose ∘ offset; permanent moments rotated into the world; group id
/// = body index; H0 from the scene. Induced moments start unmagnetized.
mag::MomentSet moment_set_at_rest(const engine::SceneDesc& scene);

}  // namespace magsim::scenes
