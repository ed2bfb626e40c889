// Tet frames at scale: ONE HDF5 file per frame, written collectively with MPI-IO by every rank
// (each writes its owned nodes and owned tets as one hyperslab per dataset), listed in an XDMF
// series (io/xdmf_series) that ParaView opens directly.  docs/parallel.md, "Frames at scale".
//
// Rows: rank r's owned nodes are the node rows [a_r, a_r + n_r) with a_r the exclusive prefix sum
// of the owned node counts (likewise tet rows), in the rank's local order.  Connectivity holds
// node rows: a tet's owned nodes are rows of its own rank; a ghost node's row is asked of its
// owner (one request/answer exchange with the owners of the ghost nodes the owned tets use).
//
// Layout of a frame file (`h5dump -A` shows the header):
//   /                  attributes format = "fdem-frame", version = 1, time (s), ranks, n_nodes,
//                      n_tets
//   /nodes/xyz         float64[n_nodes][3]  current positions (m)
//   /nodes/<name>      point arrays: gid int64[n_nodes], displacement, velocity float64[n][3], ...
//   /tets/connectivity int64[n_tets][4]     rows of /nodes
//   /tets/<name>       cell arrays: gid int64, piece, body, material int32, stress float64[n][9],
//                      von_mises, damage float64[n_tets], ...
// The file is written under `<file>.tmp`, flushed, closed and renamed by rank 0, so a frame file
// under its final name is always complete.
#pragma once

#include <cstdint>
#include <string>
#include <utility>
#include <vector>

#include "core/frame_arrays.hpp"
#include "parallel/communicator.hpp"

namespace fdem {

// MPI-IO hints (MPI_Info key, value) for the frame files: striping_factor, striping_unit,
// romio_cb_write, cb_nodes, ...  MPI-IO ignores keys it does not know.
using MpiIoHints = std::vector<std::pair<std::string, std::string>>;

// The scene's hints with those of `environment` ("key=value,key=value", the text of
// FDEM_MPIIO_HINTS, or nullptr) added; a key given in both takes the environment's value.
// Throws InputError naming FDEM_MPIIO_HINTS for an entry that is not key=value.
MpiIoHints merge_mpi_io_hints(const MpiIoHints& scene, const char* environment);

// This process alone (MPI_COMM_SELF): the communicator of a one-rank run that has none.  Throws
// InputError when MPI is not initialised.
Communicator process_communicator();

// One rank's share of a frame, as plain arrays.
struct XdmfFrameRows {
  LocalIndex n_owned = 0;                // local nodes [0, n_owned) are this rank's node rows
  std::vector<GlobalId> node_gid;        // per local node (owned first, then ghosts)
  std::vector<std::int32_t> node_owner;  // per local node: its owner's rank (read for ghosts)
  std::vector<double> node_x;            // 3 per owned node (m)
  std::vector<LocalIndex> tet_nodes;     // 4 per written (owned) tet: local node indices
  std::vector<FrameColumn> arrays;       // per_cell: per written tet; else per owned node
};

// Collective.  Writes `directory/file` (file relative to the series directory, e.g.
// "frames/frames_000003.h5") through its .tmp with MPI-IO `hints`, and returns what the series
// file needs (the same on every rank).  Every rank must pass arrays with the same names, types
// and components.  A violation (a ghost node its owner does not know, mismatched arrays) throws
// CollectiveInternalError on every rank; a file that cannot be written (no room for it, no
// permission) throws CollectiveIoError on every rank naming it (the .tmp is removed).  A data
// write that fails on some ranks only, past the space claim, ends every rank (exit code 4).
FrameFileInfo write_xdmf_frame(const std::string& directory, const std::string& file, double time,
                               const Communicator& comm, const XdmfFrameRows& rows,
                               const MpiIoHints& hints = {});

}  // namespace fdem
