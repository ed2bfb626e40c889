// Checkpoint files: the whole run state in ONE parallel-HDF5 file, written collectively by every
// rank (each writes the rows it owns) and readable by any number of ranks.
//
// Layout (self-describing; `h5dump -A` shows the header):
//   /                 attributes format = "fdem-checkpoint", version = 3, ranks, n_nodes, n_tets,
//                     n_joints, reference_hash, fields (the datasets below the gids, as
//                     "group/name:type[components]" separated by spaces), header_checksum (of
//                     the counts, the /run values and the field list)
//   /run/<name>       one scalar dataset per named value: float64 for header.doubles, int64 for
//                     header.integers, in the order the driver gave them (creation order tracked)
//   /nodes/gid        int64[n_nodes] = 0..n_nodes-1 (row i is the node of gid i; the driver
//                     stores gid − Model::gid_offset, with /run/gid_offset for the record)
//   /nodes/<field>    one dataset per node field that checkpoints (core/fields.hpp: x, v,
//                     prescribed_velocity, x_at_detection): [n_nodes] for one component,
//                     [n_nodes][components] for more
//   /joints/gid       int64[n_joints] = 0..n_joints-1
//   /joints/<field>   the joint fields that checkpoint (broken, mode, failure_time, damage) and
//                     history, uint8[n_joints][bytes] (the fracture stage's opaque records)
//   /friction/{a, b}  int64[m] (tet gids a < b, less the offset too), and one float64 dataset
//                     per pair field (spring [m][3], stiffness [m]); written in rank order, read
//                     back sorted by (a, b)
//
// Every dataset has a uint64 attribute `checksum` (parallel/checkpoint_checksum.hpp: a sum over
// its rows, so each rank adds its block); reading verifies each one and the header's, and a
// mismatch is an InputError "checkpoint corrupt: dataset /nodes/x ...".
//
// The write goes to `path + ".tmp"`, is flushed to storage and closed, and only then renamed to
// `path` by rank 0 (an atomic replace on POSIX file systems), so a crash during the write never
// leaves a torn file under the final name.
#pragma once

#include <cstddef>
#include <cstdint>
#include <functional>
#include <string>
#include <type_traits>
#include <utility>
#include <variant>
#include <vector>

#include "core/fields.hpp"
#include "core/types.hpp"
#include "parallel/communicator.hpp"

namespace fdem {

// Format version written into and required from every checkpoint file.
// 2: checksums; 3: datasets from the field tables (core/fields.hpp), listed in the root
// attribute `fields`; 4: friction pairs carry their stick springs' anchors.
constexpr int checkpoint_format_version = 4;

// The run state a restart needs, beside the rows: named scalars chosen by the driver.
struct CheckpointHeader {
  std::int64_t n_nodes = 0, n_tets = 0, n_joints = 0;  // global counts (scene check on restart)
  std::uint64_t reference_hash = 0;  // hash of reference positions: the scene must match
  int ranks = 1;  // ranks that wrote the file (write_checkpoint stores comm.size(), not this)
  std::vector<std::pair<std::string, double>> doubles;         // time, dt, ledger terms, ...
  std::vector<std::pair<std::string, std::int64_t>> integers;  // step, detections, ...
};

// The values of one dataset: `components` per row, row after row.  The alternatives are in
// ValueType order (float64, int32, uint8).
using CheckpointValues =
    std::variant<std::vector<double>, std::vector<std::int32_t>, std::vector<std::uint8_t>>;
struct CheckpointColumn {
  std::string name;  // the dataset's name in its group
  std::size_t components = 1;
  CheckpointValues values;

  ValueType type() const { return static_cast<ValueType>(values.index()); }
  std::size_t size() const {
    return std::visit([](const auto& v) { return v.size(); }, values);
  }
  // "name:type[components]", as the root attribute `fields` lists it.
  std::string description() const;
  // The same dataset with the values f(values) (f maps a std::vector<T> to a std::vector<T>).
  template <class F>
  CheckpointColumn with_values(F&& f) const {
    CheckpointColumn out;
    out.name = name;
    out.components = components;
    out.values = std::visit([&](const auto& v) { return CheckpointValues(f(v)); }, values);
    return out;
  }
};

// A group of rows: their keys and one column per dataset.
struct CheckpointTable {
  std::vector<GlobalId> gid;  // nodes and joints: dense 0..n-1 overall
  std::vector<CheckpointColumn> columns;
  const CheckpointColumn& column(const std::string& name) const;  // FDEM_VERIFY that it is there
};

// One rank's share of a checkpoint (what it owns), or after reading, what it asked for, sorted by
// gid (pairs by (a, b)).
struct CheckpointRows {
  CheckpointTable nodes, joints;
  std::vector<GlobalId> pair_a, pair_b;        // friction pairs (a < b), any count
  std::vector<CheckpointColumn> pair_columns;  // float64 only

  // The datasets' list (the root attribute `fields`): the same for every rank of one write.
  std::string field_list() const;
};

// Collective.  Writes `path` via `path + ".tmp"` (MPI-IO on comm.handle()), flushes and closes
// it, then rank 0 renames it to `path` and every rank waits for that.  Node and joint rows go to
// their gid positions: the owned rows first move (MPI_Alltoallv) to the rank whose contiguous
// block of gids holds them, then every rank writes its block as one hyperslab with collective
// I/O (a rank with no rows still takes part).  Friction rows are appended in rank order.
//
// Checked first, on every rank together: the header is the same on every rank, the columns have
// one row per key, friction pairs have a < b, the field list agrees, and the owned
// node / joint gids of all ranks form exactly 0..n-1 once each.  A violation is a bug of the
// caller and throws CollectiveInternalError on every rank.  A file that cannot be created or an
// HDF5 failure (disk full) throws CollectiveIoError on every rank, naming the file; the .tmp file
// is then removed and an existing file at `path` is left as it was.
void write_checkpoint(const std::string& path, const Communicator& comm,
                      const CheckpointHeader& header, const CheckpointRows& owned);

// The rows a rank needs from a checkpoint, by gid (each list ascending, without repeats): the
// nodes and joints it holds, and the tets whose friction pairs it keeps (a pair (a, b) goes to
// every rank that lists its first tet a).
struct CheckpointWanted {
  std::vector<GlobalId> nodes, joints, tets;
};

// Collective.  Reads the header on every rank (with `layout`, the file's field list must be
// `layout.field_list()`, else an InputError names both), then each rank reads one contiguous block
// of every dataset by hyperslab (collective I/O), the ranks verify the datasets' checksums
// together, and the rows travel from the block ranks to the ranks that want them: a rank reads and
// receives its block and its wanted rows, never the whole file.  Rows come back in the order of
// `wanted`, friction pairs sorted by (a, b).  `check_header` (optional) runs on every rank once the
// header is read, before any row (a scene mismatch is reported there; what it throws becomes a
// collective failure).  Without `wanted`, every rank gets every row (small files, tests); without
// `layout`, the columns the file lists.
//
// A missing file, a file that is not an fdem checkpoint, a different format version, a dataset
// of the wrong size or type, one that does not match its checksum ("checkpoint corrupt: dataset
// X"), or a wanted gid beyond the file's counts throws CollectiveInputError on every rank naming
// the file and what is wrong.
std::pair<CheckpointHeader, CheckpointRows> read_checkpoint(
    const std::string& path, const Communicator& comm, const CheckpointWanted* wanted,
    const std::function<void(const CheckpointHeader&)>& check_header,
    const CheckpointRows* layout = nullptr);
std::pair<CheckpointHeader, CheckpointRows> read_checkpoint(const std::string& path,
                                                            const Communicator& comm);

}  // namespace fdem
