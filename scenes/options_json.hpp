// scenes/options_json.hpp — the run options (SimOptions, with its mag::DynamicsOptions and
// mag::FieldOptions) as JSON, one spelling for everything that reads or writes them: the
// scene file's "options" object (SCENE_FILE.md), summary.json's "options", --write-scene and
// magsolve's case "magnetics". Both go through the table of options (engine/options_table.hpp):
// the layout is the structs' ("magnetics": {"field": {"bh_theta": …}}), to_json writes every
// option, from_json reads them back, so from_json(to_json(o)) == o, and a summary's options
// replayed as a scene file rerun the run. from_json also reads the keys of files written before
// the layout followed the structs ("bh_theta" for "magnetics.field.bh_theta").
#pragma once

#include "engine/scene_desc.hpp"
#include "scenes/json_reader.hpp"

#include <nlohmann/json.hpp>

#include <string>

namespace magsim::scenes {

/// Every option under its key, nested as the structs are ("dt", "space", "magnetics": {…}).
nlohmann::json to_json(const engine::SimOptions& o);

/// Reads the keys present in `j` (an "options" object at `path`) into *o, each checked against
/// its entry in the table; keys absent keep *o's values. Throws std::runtime_error via r: an
/// unknown key, a bad value, or an option given under both its key and its older one.
void from_json(const JsonReader& r, const nlohmann::json& j, const std::string& path, engine::SimOptions* o);
/// The same for a "magnetics" object (a scene file's options.magnetics: method, field, …).
void from_json(const JsonReader& r, const nlohmann::json& j, const std::string& path, mag::DynamicsOptions* d);

/// The table of options (engine/options_table.hpp) as JSON, one object per option in the
/// table's order: key, old_key, kind (number, integer, bool, name, vector), unit, default (a
/// JSON value) and default_text (as SCENE_FILE.md spells it), values (the text SCENE_FILE.md gives), flag, flag_switch, doc, and
/// range {integer, lo, hi, lo_open, hi_open} or names. magsim-scene --options-json prints it.
nlohmann::json table_json();
/// [x, y, z]: how scene files, summary.json and the options write a vector.
inline nlohmann::json vec3_json(const Eigen::Vector3d& v) { return nlohmann::json::array({v.x(), v.y(), v.z()}); }

}  // namespace magsim::scenes
