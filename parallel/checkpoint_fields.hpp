// Checkpoint rows from the field tables (core/fields.hpp) and back: the datasets of a checkpoint
// are the fields declared with FieldUse::checkpoint, the stages' node fields, the joint records
// and the pair records, so a field added to a table is written and restored without more code.
#pragma once

#include <cstddef>

#include "core/model.hpp"
#include "core/travelling_state.hpp"
#include "parallel/checkpoint.hpp"

namespace fdem {

// The columns this build writes and restores, with no rows.  `joint_record_bytes`: the size of
// the fracture stage's per-joint record (0: none).
CheckpointRows checkpoint_layout(std::size_t joint_record_bytes);

// The rows this rank writes: its owned nodes, the joints whose tet A it owns and the pairs whose
// tet a it owns, keyed by gid − model.gid_offset.
CheckpointRows owned_checkpoint_rows(const Model& model, const TravellingState& state);

// Rows read from a checkpoint (keys gid − gid_offset) into the entries held here: the checkpoint
// fields of the nodes and joints, the state's node fields and joint records (sized for the model
// before), and as state.pairs the pairs whose tet a is held.  Rows of entries not held here are
// skipped.
void store_checkpoint_rows(const CheckpointRows& rows, Model& model, TravellingState& state);

}  // namespace fdem
