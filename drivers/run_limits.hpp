// Limits between a valid scene and a runnable one: the memory a rank will need and the number of
// time steps, estimated before anything large is allocated and refused beyond the ceilings of
// the scene's `limits:` block (docs/scene-format.md) with the numbers and the key to change.
#pragma once

#include <functional>
#include <string>

#include "core/model.hpp"
#include "core/scene.hpp"

namespace fdem {

// Sizes of a model, as doubles: an estimate must not overflow on the sizes it exists to refuse.
struct ModelSize {
  double nodes = 0.0, tets = 0.0, joints = 0.0;
};

// Nodes, tets and joints the scene's generated meshes will have, from the mesh specs alone (no
// allocation).  File meshes count zero here: their size is checked once they are read (the
// readers allocate in proportion to the file).
ModelSize estimate_generated_size(const Scene& scene);
ModelSize model_size(const Model& model);

// Bytes one rank needs at its peak for a model of `size` run on `ranks` ranks (every rank builds
// the whole model before keeping its part, unless `distributed_start`).
double estimated_bytes_per_rank(const ModelSize& size, int ranks, bool distributed_start = false);

// The memory one rank may use: limits.max_memory_per_rank, or when automatic the smallest of the
// node's memory (physical, cgroup limit) shared by `ranks_on_node` ranks and this process's
// ulimit -v / -d.  `source` (optional) receives where the value came from, for messages.
double memory_ceiling_per_rank(const LimitsSpec& limits, int ranks_on_node,
                               std::string* source = nullptr);

// Throws InputError when the estimate for `size` exceeds the ceiling.  `what`: "the scene's
// generated meshes" or "the model".
void check_memory_limit(const Scene& scene, const ModelSize& size, int ranks, int ranks_on_node,
                        bool distributed_start, const std::string& what);

// Time steps from `start` to `end` with step `dt` (s), as a double (may be huge).
double step_count(double start, double end, double dt);

// Throws InputError when the steps from `start` to time.end exceed limits.max_steps (or do not
// fit a long).  `step_origin` explains the time step (which element or stiffness sets it); it is
// only called for the message (it scans the model).
void check_step_limit(const Scene& scene, double start, double dt,
                      const std::function<std::string()>& step_origin);

// The step count of a run already checked by check_step_limit.
long checked_step_count(double start, double end, double dt);

// "tetrahedron G of body 'B' (smallest height H m)": the element that sets a critical step.
std::string describe_tet(const Model& model, LocalIndex tet);

// A human-readable byte count ("3.2 GB").
std::string format_bytes(double bytes);

}  // namespace fdem
