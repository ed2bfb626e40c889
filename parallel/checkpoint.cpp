#include "parallel/checkpoint.hpp"

#include <hdf5.h>

#include <algorithm>
#include <array>
#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <map>
#include <numeric>
#include <set>
#include <sstream>
#include <type_traits>

#include "core/error.hpp"
#include "parallel/checkpoint_checksum.hpp"
#include "parallel/checkpoint_format.hpp"
#include "parallel/checkpoint_seal.hpp"
#include "parallel/hdf5_support.hpp"

namespace fdem {

using namespace hdf5;  // Handle, Context, Writer, ... (shared with parallel/xdmf_output.cpp)
using namespace checkpoint_format;  // format_name, serialized, header_checksum, GidBlocks

namespace {

// ---------------------------------------------------------------------------------------------
// Checks of the caller's rows (a violation is a bug of the caller: internal error).

void check_run_names(const CheckpointHeader& header) {
  std::set<std::string> names;
  auto check = [&](const std::string& name) {
    FDEM_VERIFY(!name.empty() && name != "." && name.find('/') == std::string::npos,
                "checkpoint value name '" + name + "' is empty or contains '/'");
    FDEM_VERIFY(names.insert(name).second, "checkpoint value name '" + name + "' given twice");
  };
  for (const auto& entry : header.doubles) check(entry.first);
  for (const auto& entry : header.integers) check(entry.first);
}

void check_local_rows(const CheckpointHeader& header, const CheckpointRows& rows) {
  FDEM_VERIFY(header.n_nodes >= 0 && header.n_tets >= 0 && header.n_joints >= 0,
              "checkpoint header has a negative count");
  check_run_names(header);
  const std::size_t nodes = rows.node_gid.size();
  FDEM_VERIFY(rows.node_x.size() == 3 * nodes && rows.node_v.size() == 3 * nodes &&
                  rows.node_x_at_detection.size() == 3 * nodes &&
                  rows.node_prescribed_velocity.size() == 3 * nodes,
              "checkpoint node arrays are not 3 values per node gid");
  const std::size_t joints = rows.joint_gid.size();
  FDEM_VERIFY(rows.joint_broken.size() == joints && rows.joint_mode.size() == joints &&
                  rows.joint_failure_time.size() == joints && rows.joint_damage.size() == joints &&
                  rows.joint_history.size() == joints * rows.joint_history_bytes,
              "checkpoint joint arrays do not match the joint gids");
  const std::size_t pairs = rows.friction_a.size();
  FDEM_VERIFY(rows.friction_b.size() == pairs && rows.friction_spring.size() == 3 * pairs &&
                  rows.friction_stiffness.size() == pairs,
              "checkpoint friction arrays do not match the pair count");
  for (std::size_t k = 0; k < pairs; ++k)
    FDEM_VERIFY(rows.friction_a[k] < rows.friction_b[k],
                "checkpoint friction pair without a < b: (" + std::to_string(rows.friction_a[k]) +
                    ", " + std::to_string(rows.friction_b[k]) + ")");
  auto check_gids = [](const std::vector<GlobalId>& gids, std::int64_t n, const char* what) {
    std::vector<GlobalId> sorted = gids;
    std::sort(sorted.begin(), sorted.end());
    for (std::size_t k = 0; k < sorted.size(); ++k) {
      FDEM_VERIFY(sorted[k] >= 0 && sorted[k] < n, std::string("checkpoint ") + what + " gid " +
                                                       std::to_string(sorted[k]) + " outside 0.." +
                                                       std::to_string(n - 1));
      FDEM_VERIFY(k == 0 || sorted[k] != sorted[k - 1], std::string("checkpoint ") + what +
                                                            " gid " + std::to_string(sorted[k]) +
                                                            " given twice on one rank");
    }
  };
  check_gids(rows.node_gid, header.n_nodes, "node");
  check_gids(rows.joint_gid, header.n_joints, "joint");
}

// ---------------------------------------------------------------------------------------------
// Rows to file blocks.  Rank r writes the contiguous gid block [begin(r), begin(r+1)) of every
// node and joint dataset: the owned rows travel to the rank of their block first (one all-to-all
// per array), so that each rank writes one hyperslab with collective I/O.  (A union of one
// hyperslab per run of owned gids costs HDF5 1.10 time growing faster than quadratically in the
// number of runs: 7.5 s to build the selection of 20 000 runs, far more in the write.)

class BlockExchange {
 public:
  // Collective.  `gids` lie in 0..n-1 (checked before).
  BlockExchange(const Communicator& comm, const std::vector<GlobalId>& gids, std::int64_t n,
                const char* what)
      : comm_(comm) {
    const int ranks = comm.size();
    const GidBlocks blocks{n, ranks};
    begin_ = blocks.begin(comm.rank());
    rows_ = blocks.count(comm.rank());
    auto owner = [&](GlobalId g) { return blocks.owner(g); };

    // Local rows grouped by destination rank (a counting sort keeps it linear).  Counts and
    // offsets are 64-bit (Communicator::exchange_rows).
    std::vector<int> destination(gids.size());
    std::vector<std::size_t> counts(static_cast<std::size_t>(ranks), 0);
    for (std::size_t i = 0; i < gids.size(); ++i)
      ++counts[static_cast<std::size_t>(destination[i] = owner(gids[i]))];
    send_counts_.assign(counts.begin(), counts.end());
    std::vector<std::int64_t> next(static_cast<std::size_t>(ranks), 0);
    for (int r = 1; r < ranks; ++r) next[r] = next[r - 1] + send_counts_[r - 1];
    send_order_.resize(gids.size());
    for (std::size_t i = 0; i < gids.size(); ++i)
      send_order_[static_cast<std::size_t>(next[static_cast<std::size_t>(destination[i])]++)] = i;
    recv_counts_ = comm.exchange_counts(counts);
    for (std::int64_t c : recv_counts_) received_rows_ += static_cast<std::size_t>(c);

    // Where each received row goes in the block: the gids of all ranks are 0..n-1 exactly once
    // iff every block slot of every rank is hit exactly once.
    const std::vector<GlobalId> received = exchange(gids, 1);
    slot_.resize(received.size());
    std::vector<std::uint8_t> hits(static_cast<std::size_t>(rows_), 0);
    for (std::size_t k = 0; k < received.size(); ++k) {
      slot_[k] = static_cast<std::size_t>(received[k] - begin_);
      if (received[k] < begin_ || received[k] >= begin_ + rows_) {  // cannot happen: owner()
        problem_ = std::string(what) + " gid " + std::to_string(received[k]) + " sent astray";
        slot_.clear();
        break;
      }
      if (hits[slot_[k]]++ && problem_.empty())
        problem_ = std::string(what) + " gid " + std::to_string(received[k]) +
                   " is owned by more than one rank";
    }
    for (std::size_t s = 0; s < hits.size() && problem_.empty(); ++s)
      if (!hits[s])
        problem_ = std::string(what) + " gid " + std::to_string(begin_ + std::int64_t(s)) +
                   " is owned by no rank (of " + std::to_string(n) + ")";
  }

  // Empty when every gid of this rank's block arrived exactly once.
  const std::string& problem() const { return problem_; }
  Run block() const { return {static_cast<hsize_t>(begin_), static_cast<hsize_t>(rows_)}; }

  // Collective.  This rank's block of an array of `width` values per owned row, in gid order.
  template <class T>
  std::vector<T> to_block(const std::vector<T>& values, std::size_t width) const {
    const std::vector<T> received = exchange(values, width);
    std::vector<T> block(static_cast<std::size_t>(rows_) * width);
    for (std::size_t k = 0; k < slot_.size(); ++k)
      std::copy_n(received.begin() + static_cast<std::ptrdiff_t>(k * width), width,
                  block.begin() + static_cast<std::ptrdiff_t>(slot_[k] * width));
    return block;
  }

 private:
  // Rows (`width` values of T each) sent to their block ranks, in the order received.
  template <class T>
  std::vector<T> exchange(const std::vector<T>& values, std::size_t width) const {
    static_assert(std::is_trivially_copyable_v<T>, "rows travel as bytes");
    std::vector<T> received(received_rows_ * width);
    if (width == 0) return received;  // the same on every rank (checked)
    std::vector<T> send(values.size());
    for (std::size_t i = 0; i < send_order_.size(); ++i)
      std::copy_n(values.begin() + static_cast<std::ptrdiff_t>(send_order_[i] * width), width,
                  send.begin() + static_cast<std::ptrdiff_t>(i * width));
    comm_.exchange_rows(send.data(), send_counts_, received.data(), recv_counts_,
                        width * sizeof(T));
    return received;
  }

  Communicator comm_;
  std::int64_t begin_ = 0, rows_ = 0;
  std::vector<std::int64_t> send_counts_, recv_counts_;  // rows per rank
  std::vector<std::size_t> send_order_, slot_;
  std::size_t received_rows_ = 0;
  std::string problem_;
};

// This rank's block of the node and joint datasets (gid order) and its own friction pairs.
struct FileBlock {
  Run nodes, joints;
  CheckpointRows rows;
  hsize_t friction_offset = 0, friction_total = 0;  // this rank's first friction row, all rows
  std::map<std::string, std::uint64_t> checksums;   // of every dataset, over all ranks
};

// Every dataset's checksum (checkpoint_checksum.hpp): this rank's rows, summed over the ranks.
// Collective.
void compute_checksums(const Communicator& comm, FileBlock& block) {
  const CheckpointRows& r = block.rows;
  const std::uint64_t node0 = block.nodes.start, joint0 = block.joints.start;
  const std::uint64_t pair0 = block.friction_offset;
  const std::vector<std::pair<std::string, std::uint64_t>> local = {
      {"/nodes/gid", rows_checksum("/nodes/gid", r.node_gid, 1, node0)},
      {"/nodes/x", rows_checksum("/nodes/x", r.node_x, 3, node0)},
      {"/nodes/v", rows_checksum("/nodes/v", r.node_v, 3, node0)},
      {"/nodes/x_at_detection",
       rows_checksum("/nodes/x_at_detection", r.node_x_at_detection, 3, node0)},
      {"/nodes/prescribed_velocity",
       rows_checksum("/nodes/prescribed_velocity", r.node_prescribed_velocity, 3, node0)},
      {"/joints/gid", rows_checksum("/joints/gid", r.joint_gid, 1, joint0)},
      {"/joints/broken", rows_checksum("/joints/broken", r.joint_broken, 1, joint0)},
      {"/joints/mode", rows_checksum("/joints/mode", r.joint_mode, 1, joint0)},
      {"/joints/failure_time",
       rows_checksum("/joints/failure_time", r.joint_failure_time, 1, joint0)},
      {"/joints/damage", rows_checksum("/joints/damage", r.joint_damage, 1, joint0)},
      {"/joints/history",
       rows_checksum("/joints/history", r.joint_history, r.joint_history_bytes, joint0)},
      {"/friction/a", rows_checksum("/friction/a", r.friction_a, 1, pair0)},
      {"/friction/b", rows_checksum("/friction/b", r.friction_b, 1, pair0)},
      {"/friction/spring", rows_checksum("/friction/spring", r.friction_spring, 3, pair0)},
      {"/friction/stiffness",
       rows_checksum("/friction/stiffness", r.friction_stiffness, 1, pair0)}};
  std::vector<std::uint64_t> sums;
  for (const auto& entry : local) sums.push_back(entry.second);
  comm.sum_in_place(sums);  // unsigned: wraps mod 2^64, the same on any rank count
  for (std::size_t i = 0; i < local.size(); ++i) block.checksums[local[i].first] = sums[i];
}

// ---------------------------------------------------------------------------------------------
// Writing.

// Where every dataset's raw data lies in the file (for the seal).  Collective (metadata reads).
std::vector<FileRegion> data_regions(const Context& ctx, hid_t file) {
  std::vector<FileRegion> regions;
  for (const char* name :
       {"/nodes/gid", "/nodes/x", "/nodes/v", "/nodes/x_at_detection", "/nodes/prescribed_velocity",
        "/joints/gid", "/joints/broken", "/joints/mode", "/joints/failure_time", "/joints/damage",
        "/joints/history", "/friction/a", "/friction/b", "/friction/spring",
        "/friction/stiffness"}) {
    Handle dataset =
        ctx.own(H5Dopen2(file, name, H5P_DEFAULT), H5Dclose, std::string("cannot open ") + name);
    const haddr_t address = H5Dget_offset(dataset.get());  // from the start of the file
    const hsize_t size = H5Dget_storage_size(dataset.get());
    if (address != HADDR_UNDEF && size > 0) regions.push_back({address, size});
  }
  return regions;
}

// Writes the file; returns where its datasets' raw data lie.
std::vector<FileRegion> write_file(const Context& ctx, const std::string& tmp_path,
                                   const Communicator& comm, const CheckpointHeader& header,
                                   const FileBlock& block) {
  Handle file;
  comm.run_collectively([&] {
    Handle fapl = make_mpio_access(ctx, comm);
    Handle fcpl = make_plist(ctx, H5P_FILE_CREATE);  // the userblock holds the seal
    ctx.check_status(H5Pset_userblock(fcpl.get(), checkpoint_seal_bytes), "cannot set userblock");
    file = ctx.own(H5Fcreate(tmp_path.c_str(), H5F_ACC_TRUNC, fcpl.get(), fapl.get()), H5Fclose,
                   "cannot create '" + tmp_path + "'");
  });

  // Root attributes and the named run values.
  comm.run_collectively([&] {
    const Writer write(ctx, file.get());
    const hid_t root = file.get();
    const std::int32_t version = checkpoint_format_version, ranks = comm.size();
    const auto history_bytes = static_cast<std::int64_t>(block.rows.joint_history_bytes);
    write.string_attribute(root, "format", format_name);
    write.attribute(root, "version", H5T_STD_I32LE, H5T_NATIVE_INT32, &version);
    write.attribute(root, "ranks", H5T_STD_I32LE, H5T_NATIVE_INT32, &ranks);
    write.attribute(root, "n_nodes", H5T_STD_I64LE, H5T_NATIVE_INT64, &header.n_nodes);
    write.attribute(root, "n_tets", H5T_STD_I64LE, H5T_NATIVE_INT64, &header.n_tets);
    write.attribute(root, "n_joints", H5T_STD_I64LE, H5T_NATIVE_INT64, &header.n_joints);
    write.attribute(root, "reference_hash", H5T_STD_U64LE, H5T_NATIVE_UINT64,
                    &header.reference_hash);
    write.attribute(root, "joint_history_bytes", H5T_STD_I64LE, H5T_NATIVE_INT64, &history_bytes);
    const std::uint64_t checksum = header_checksum(serialized(header), history_bytes);
    write.attribute(root, "header_checksum", H5T_STD_U64LE, H5T_NATIVE_UINT64, &checksum);
    Handle run = write.group("run", /*track_attribute_order=*/true);
    for (const auto& [name, value] : header.doubles)
      write.attribute(run.get(), name, H5T_IEEE_F64LE, H5T_NATIVE_DOUBLE, &value);
    for (const auto& [name, value] : header.integers)
      write.attribute(run.get(), name, H5T_STD_I64LE, H5T_NATIVE_INT64, &value);
  });

  // Nodes and joints: this rank's block of gids, one hyperslab per dataset.
  const CheckpointRows& rows = block.rows;
  comm.run_collectively([&] {
    const Writer write(ctx, file.get());
    const auto n = static_cast<hsize_t>(header.n_nodes);
    std::vector<Run> runs;
    if (block.nodes.count > 0) runs.push_back(block.nodes);
    Handle nodes = write.group("nodes");
    write.rows(nodes.get(), "gid", n, 0, rows.node_gid, runs, block.checksums.at("/nodes/gid"));
    write.rows(nodes.get(), "x", n, 3, rows.node_x, runs, block.checksums.at("/nodes/x"));
    write.rows(nodes.get(), "v", n, 3, rows.node_v, runs, block.checksums.at("/nodes/v"));
    write.rows(nodes.get(), "x_at_detection", n, 3, rows.node_x_at_detection, runs,
               block.checksums.at("/nodes/x_at_detection"));
    write.rows(nodes.get(), "prescribed_velocity", n, 3, rows.node_prescribed_velocity, runs,
               block.checksums.at("/nodes/prescribed_velocity"));
  });

  comm.run_collectively([&] {
    const Writer write(ctx, file.get());
    const auto n = static_cast<hsize_t>(header.n_joints);
    const hsize_t bytes = rows.joint_history_bytes;
    std::vector<Run> runs;
    if (block.joints.count > 0) runs.push_back(block.joints);
    Handle joints = write.group("joints");
    write.rows(joints.get(), "gid", n, 0, rows.joint_gid, runs, block.checksums.at("/joints/gid"));
    write.rows(joints.get(), "broken", n, 0, rows.joint_broken, runs,
               block.checksums.at("/joints/broken"));
    write.rows(joints.get(), "mode", n, 0, rows.joint_mode, runs,
               block.checksums.at("/joints/mode"));
    write.rows(joints.get(), "failure_time", n, 0, rows.joint_failure_time, runs,
               block.checksums.at("/joints/failure_time"));
    write.rows(joints.get(), "damage", n, 0, rows.joint_damage, runs,
               block.checksums.at("/joints/damage"));
    // history is n × bytes even for bytes = 0, so the record size is visible in the file.
    if (bytes == 0) {
      Handle history_space = make_space(ctx, {n, bytes});
      const Handle empty_history =
          ctx.own(H5Dcreate2(joints.get(), "history", H5T_STD_U8LE, history_space.get(),
                             H5P_DEFAULT, H5P_DEFAULT, H5P_DEFAULT),
                  H5Dclose, "cannot create dataset history");
      const std::uint64_t none = 0;  // no rows
      write.attribute(empty_history.get(), "checksum", H5T_STD_U64LE, H5T_NATIVE_UINT64, &none);
    } else {
      write.rows(joints.get(), "history", n, bytes, rows.joint_history, runs,
                 block.checksums.at("/joints/history"));
    }
  });

  // Friction pairs: this rank's rows after those of the lower ranks.
  comm.run_collectively([&] {
    const Writer write(ctx, file.get());
    const hsize_t offset = block.friction_offset, total = block.friction_total;
    std::vector<Run> runs;
    if (!rows.friction_a.empty()) runs.push_back({offset, rows.friction_a.size()});
    Handle friction = write.group("friction");
    write.rows(friction.get(), "a", total, 0, rows.friction_a, runs,
               block.checksums.at("/friction/a"));
    write.rows(friction.get(), "b", total, 0, rows.friction_b, runs,
               block.checksums.at("/friction/b"));
    write.rows(friction.get(), "spring", total, 3, rows.friction_spring, runs,
               block.checksums.at("/friction/spring"));
    write.rows(friction.get(), "stiffness", total, 0, rows.friction_stiffness, runs,
               block.checksums.at("/friction/stiffness"));
  });

  std::vector<FileRegion> regions;
  comm.run_collectively([&] { regions = data_regions(ctx, file.get()); });
  // Flush to storage (MPI_File_sync), then close: only a complete file gets the final name.
  comm.run_collectively([&] {
    ctx.check_collective_write(H5Fflush(file.get(), H5F_SCOPE_GLOBAL),
                               "cannot flush '" + tmp_path + "'");
    ctx.check_collective_write(file.close(), "cannot close '" + tmp_path + "'");
  });
  return regions;
}

// The file's size, about: its datasets (bytes per row) and 1 MiB for metadata.
double estimated_file_bytes(const CheckpointHeader& header, std::size_t history_bytes,
                            std::int64_t friction_pairs) {
  return double(header.n_nodes) * (8 + 4 * 24) +
         double(header.n_joints) * (8 + 1 + 1 + 8 + 8 + double(history_bytes)) +
         double(friction_pairs) * (8 + 8 + 24 + 8) + 1048576.0;
}

}  // namespace

// ---------------------------------------------------------------------------------------------
void write_checkpoint(const std::string& path, const Communicator& comm,
                      const CheckpointHeader& header, const CheckpointRows& owned) {
  Context ctx(path, "checkpoint", Context::Mode::write);
  ctx.abort_on(comm);
  const std::string tmp_path = path + ".tmp";

  // 1. The caller's rows, first each rank's own, then across ranks (all before any file I/O, so
  //    that no rank is left alone in a collective HDF5 call).
  comm.run_collectively([&] { check_local_rows(header, owned); });
  const std::string root_header = comm.broadcast(serialized(header), 0);
  const auto history_bytes = static_cast<std::uint64_t>(owned.joint_history_bytes);
  const bool same_history_bytes = comm.min(history_bytes) == comm.max(history_bytes);
  comm.run_collectively([&] {
    FDEM_VERIFY(root_header == serialized(header),
                "checkpoint header differs between rank 0 and rank " + std::to_string(comm.rank()));
    FDEM_VERIFY(same_history_bytes, "checkpoint joint_history_bytes differs between ranks");
  });
  // Rows to the ranks of their file blocks; the block ranks see whether every gid arrived once.
  const BlockExchange node_exchange(comm, owned.node_gid, header.n_nodes, "node");
  const BlockExchange joint_exchange(comm, owned.joint_gid, header.n_joints, "joint");
  comm.run_collectively([&] {
    FDEM_VERIFY(node_exchange.problem().empty(), "checkpoint rows: " + node_exchange.problem());
    FDEM_VERIFY(joint_exchange.problem().empty(), "checkpoint rows: " + joint_exchange.problem());
  });
  FileBlock block;
  block.nodes = node_exchange.block();
  block.joints = joint_exchange.block();
  CheckpointRows& rows = block.rows;
  rows.node_gid.resize(block.nodes.count);
  std::iota(rows.node_gid.begin(), rows.node_gid.end(), GlobalId(block.nodes.start));
  rows.node_x = node_exchange.to_block(owned.node_x, 3);
  rows.node_v = node_exchange.to_block(owned.node_v, 3);
  rows.node_x_at_detection = node_exchange.to_block(owned.node_x_at_detection, 3);
  rows.node_prescribed_velocity = node_exchange.to_block(owned.node_prescribed_velocity, 3);
  rows.joint_gid.resize(block.joints.count);
  std::iota(rows.joint_gid.begin(), rows.joint_gid.end(), GlobalId(block.joints.start));
  rows.joint_broken = joint_exchange.to_block(owned.joint_broken, 1);
  rows.joint_mode = joint_exchange.to_block(owned.joint_mode, 1);
  rows.joint_failure_time = joint_exchange.to_block(owned.joint_failure_time, 1);
  rows.joint_damage = joint_exchange.to_block(owned.joint_damage, 1);
  rows.joint_history_bytes = owned.joint_history_bytes;
  rows.joint_history = joint_exchange.to_block(owned.joint_history, owned.joint_history_bytes);
  rows.friction_a = owned.friction_a;
  rows.friction_b = owned.friction_b;
  rows.friction_spring = owned.friction_spring;
  rows.friction_stiffness = owned.friction_stiffness;
  const std::vector<std::int64_t> pair_counts =
      comm.allgather(static_cast<std::int64_t>(rows.friction_a.size()));
  for (int r = 0; r < comm.size(); ++r) {
    if (r < comm.rank()) block.friction_offset += static_cast<hsize_t>(pair_counts[r]);
    block.friction_total += static_cast<hsize_t>(pair_counts[r]);
  }
  compute_checksums(comm, block);

  // 2. The file under its temporary name, its space claimed first.  A failure is collective:
  //    every rank unwinds (closing the file together) and rank 0 removes the partial file.
  comm.run_collectively([&] {
    if (comm.is_root())
      reserve_space(ctx, tmp_path,
                    estimated_file_bytes(header, owned.joint_history_bytes,
                                         static_cast<std::int64_t>(block.friction_total)));
  });
  std::vector<FileRegion> regions;
  {
    const SilenceHdf5Errors silence;
    try {
      regions = write_file(ctx, tmp_path, comm, header, block);
    } catch (const CollectiveFailure&) {
      if (comm.is_root()) std::remove(tmp_path.c_str());
      throw;
    }
  }

  // 3. The seal, then the final name: an atomic replace by rank 0, which every rank waits for.
  comm.run_collectively([&] {
    if (!comm.is_root()) return;
    try {
      write_checkpoint_seal(tmp_path, regions);
    } catch (const IoError&) {
      std::remove(tmp_path.c_str());
      throw;
    }
    if (std::rename(tmp_path.c_str(), path.c_str()) != 0) {
      const std::string reason = std::strerror(errno);
      std::remove(tmp_path.c_str());
      ctx.fail("cannot rename '" + tmp_path + "' to the final name: " + reason);
    }
    sync_directory_of(path);
  });
}

}  // namespace fdem
