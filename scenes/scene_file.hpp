// scenes/scene_file.hpp — scenes loaded from JSON files (schema in SCENE_FILE.md), so a user
// can make a new scene without recompiling.
#pragma once

#include "engine/scene_desc.hpp"

#include <nlohmann/json.hpp>

#include <string>

namespace magsim::scenes {

/// Reads and validates a scene file. Throws std::runtime_error with a one-line message
/// naming the file and the offending field (unreadable file, malformed JSON, unknown key,
/// missing or non-finite value, negative size/volume/mass, unknown enum).
engine::SceneDesc load_scene_file(const std::string& path);
/// The same from a JSON text (`origin` names it in messages).
engine::SceneDesc parse_scene_json(const std::string& text, const std::string& origin);
/// The scene as a scene file: every field the reader reads (bodies, shapes, moments, options,
/// camera …), so parse_scene_json(scene_to_json(s).dump()) runs as s does (same state hash).
nlohmann::json scene_to_json(const engine::SceneDesc& s);

}  // namespace magsim::scenes
