// scenes/options_json.hpp — the run options (SimOptions, with its mag::DynamicsOptions and
// mag::FieldOptions) as JSON, one spelling for everything that reads or writes them: the
// scene file's "options" object (SCENE_FILE.md), summary.json's "options", --write-scene and
// magsolve's case "magnetics". to_json writes every field; from_json reads them back, so
// from_json(to_json(o)) == o, and a summary's options replayed as a scene file rerun the run.
#pragma once

#include "engine/scene_desc.hpp"
#include "scenes/json_reader.hpp"

#include <nlohmann/json.hpp>

#include <string>
#include <vector>

namespace magsim::scenes {

/// Every SimOptions field under its scene-file name ("dt", "space", "magnetics": {…}, …).
nlohmann::json to_json(const engine::SimOptions& o);
/// The "magnetics" object: every DynamicsOptions field but the method (the options' top-level
/// "method" holds it), with FieldOptions' softening and bounded_pairs (the other field options sit
/// beside it in "options": field_solver, bh_theta, bh_threshold, bh_*).
nlohmann::json to_json(const mag::DynamicsOptions& d);

/// Reads the keys present in `j` (an "options" object at `path`) into *o, checked; keys
/// absent keep *o's values. Throws std::runtime_error via r (unknown key, bad value).
void from_json(const JsonReader& r, const nlohmann::json& j, const std::string& path, engine::SimOptions* o);
/// The same for a "magnetics" object (the method is left alone).
void from_json(const JsonReader& r, const nlohmann::json& j, const std::string& path, mag::DynamicsOptions* d);

/// [x, y, z]: how scene files, summary.json and the options write a vector.
inline nlohmann::json vec3_json(const Eigen::Vector3d& v) { return nlohmann::json::array({v.x(), v.y(), v.z()}); }

}  // namespace magsim::scenes
