// A restart continues a checkpoint with the scene given now.  Geometry must match (node, tet and
// joint counts and reference positions: checked in Simulation::restore_checkpoint); the other
// scene values that shaped the stored state are kept in the checkpoint and compared here.
#pragma once

#include <map>
#include <string>
#include <utility>
#include <vector>

#include "core/scene.hpp"

namespace fdem {

// Prefix of the scene values among a checkpoint's named run values.
constexpr const char* restart_scene_prefix = "scene:";

// The scene values a restart compares, by key path ("materials.rock.density",
// "bodies.projectile.velocity.x", "loads[0].velocity.z", "gravity.z", "time.step", ...).
std::vector<std::pair<std::string, double>> restart_scene_values(const Scene& scene);

// Compares the scene with the values stored in a checkpoint (keys without the prefix).  Changes
// that make the stored state inconsistent (density, elastic constants, a body's material) throw
// InputError listing them by key; the others are returned as warnings by key, saying what the
// continuation does with them.  Keys missing on either side are changes too.
std::vector<std::string> compare_restart_scene(const Scene& scene,
                                               const std::map<std::string, double>& stored,
                                               const std::string& checkpoint);

}  // namespace fdem
