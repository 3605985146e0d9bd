// engine/limits.hpp — the magnitudes a scene may hold. Beyond them ODE's
// arithmetic overflows on the first step (1e300 m/s or m/s², an offset of 1e300 m, mass
// 1e-300 kg: inf/NaN velocities, dxNormalize4's assertion) or the magnetics do (Ms or a
// moment of 1e300). They are far outside anything physical at magsim's scales (mm–m
// bodies, 1 ms steps) and are checked by compile_model (Simulation) and, with the JSON
// path, by the scene-file loader; SCENE_FILE.md lists them.
#pragma once

namespace magsim::engine::limits {

constexpr double kMaxCoordinate = 1e6;    ///< |position|, |offset| (m)
constexpr double kMaxSize = 1e6;          ///< shape radius, half extent, half length (m)
constexpr double kMaxSpeed = 1e6;         ///< |velocity| (m/s)
constexpr double kMaxAngularSpeed = 1e6;  ///< |angular_velocity| (rad/s)
constexpr double kMaxGravity = 1e6;       ///< |gravity| (m/s²)
constexpr double kMinMass = 1e-12;        ///< a dynamic body's mass, given or density × volume (kg)
constexpr double kMaxMass = 1e12;         ///< (kg)
constexpr double kMaxMs = 1e8;            ///< saturation magnetization (A/m); iron 1.6e6
constexpr double kMaxMoment = 1e12;       ///< |permanent moment| (A·m²)
constexpr double kMaxVolume = 1e3;        ///< a moment's volume (m³)
constexpr double kMaxField = 1e12;        ///< |H0| (A/m)

}  // namespace magsim::engine::limits
