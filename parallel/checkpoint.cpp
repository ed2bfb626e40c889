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

void check_columns(const std::vector<CheckpointColumn>& columns, std::size_t rows,
                   const char* group) {
  std::set<std::string> names{"gid", "a", "b"};
  for (const CheckpointColumn& c : columns) {
    FDEM_VERIFY(!c.name.empty() && c.name.find_first_of("/: ") == std::string::npos,
                std::string("checkpoint dataset name '") + c.name + "' in " + group);
    FDEM_VERIFY(names.insert(c.name).second,
                std::string("checkpoint dataset ") + group + "/" + c.name + " given twice");
    FDEM_VERIFY(c.size() == c.components * rows,
                std::string("checkpoint dataset ") + group + "/" + c.name + " does not have " +
                    std::to_string(c.components) + " values per row");
  }
}

void check_local_rows(const CheckpointHeader& header, const CheckpointRows& rows) {
  FDEM_VERIFY(header.n_nodes >= 0 && header.n_tets >= 0 && header.n_joints >= 0,
              "checkpoint header has a negative count");
  check_run_names(header);
  check_columns(rows.nodes.columns, rows.nodes.gid.size(), "/nodes");
  check_columns(rows.joints.columns, rows.joints.gid.size(), "/joints");
  const std::size_t pairs = rows.pair_a.size();
  FDEM_VERIFY(rows.pair_b.size() == pairs, "checkpoint friction pairs: as many b as a");
  check_columns(rows.pair_columns, pairs, "/friction");
  for (const CheckpointColumn& c : rows.pair_columns)
    FDEM_VERIFY(c.type() == ValueType::f64, "checkpoint pair datasets are float64");
  for (std::size_t k = 0; k < pairs; ++k)
    FDEM_VERIFY(rows.pair_a[k] < rows.pair_b[k], "checkpoint friction pair without a < b: (" +
                                                     std::to_string(rows.pair_a[k]) + ", " +
                                                     std::to_string(rows.pair_b[k]) + ")");
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
  check_gids(rows.nodes.gid, header.n_nodes, "node");
  check_gids(rows.joints.gid, header.n_joints, "joint");
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

// Every dataset by its full name, with its rows here and the file row of the first.
template <class F>
void for_each_dataset(const FileBlock& block, F&& f) {
  const CheckpointRows& r = block.rows;
  const auto table = [&](const std::string& group, const CheckpointTable& t, std::uint64_t first) {
    f(group + "/gid", CheckpointValues{}, 1, first, &t.gid);
    for (const CheckpointColumn& c : t.columns)
      f(group + "/" + c.name, c.values, c.components, first, nullptr);
  };
  table("/nodes", r.nodes, block.nodes.start);
  table("/joints", r.joints, block.joints.start);
  f("/friction/a", CheckpointValues{}, 1, block.friction_offset, &r.pair_a);
  f("/friction/b", CheckpointValues{}, 1, block.friction_offset, &r.pair_b);
  for (const CheckpointColumn& c : r.pair_columns)
    f("/friction/" + c.name, c.values, c.components, block.friction_offset, nullptr);
}

// Every dataset's checksum (checkpoint_checksum.hpp): this rank's rows, summed over the ranks.
// Collective.
void compute_checksums(const Communicator& comm, FileBlock& block) {
  std::vector<std::string> names;
  std::vector<std::uint64_t> sums;
  for_each_dataset(
      block, [&](const std::string& name, const CheckpointValues& values, std::size_t width,
                 std::uint64_t first, const std::vector<GlobalId>* gids) {
        names.push_back(name);
        sums.push_back(
            gids ? rows_checksum(name, *gids, 1, first)
                 : std::visit([&](const auto& v) { return rows_checksum(name, v, width, first); },
                              values));
      });
  comm.sum_in_place(sums);  // unsigned: wraps mod 2^64, the same on any rank count
  for (std::size_t i = 0; i < names.size(); ++i) block.checksums[names[i]] = sums[i];
}

// ---------------------------------------------------------------------------------------------
// Writing.

// Where every dataset's raw data lies in the file (for the seal).  Collective (metadata reads).
std::vector<FileRegion> data_regions(const Context& ctx, hid_t file, const FileBlock& block) {
  std::vector<FileRegion> regions;
  for (const auto& entry : block.checksums) {
    const std::string& name = entry.first;
    Handle dataset =
        ctx.own(H5Dopen2(file, name.c_str(), H5P_DEFAULT), H5Dclose, "cannot open " + name);
    const haddr_t address = H5Dget_offset(dataset.get());  // from the start of the file
    const hsize_t size = H5Dget_storage_size(dataset.get());
    if (address != HADDR_UNDEF && size > 0) regions.push_back({address, size});
  }
  return regions;
}

// One column of `n` rows, this rank's in `runs`.
void write_column(const Context& ctx, const Writer& write, hid_t group, const CheckpointColumn& c,
                  hsize_t n, const std::vector<Run>& runs, std::uint64_t checksum) {
  if (c.components == 0) {  // n × 0, so that the record size is visible in the file
    Handle space = make_space(ctx, {n, 0});
    const Handle empty = ctx.own(H5Dcreate2(group, c.name.c_str(), H5T_STD_U8LE, space.get(),
                                            H5P_DEFAULT, H5P_DEFAULT, H5P_DEFAULT),
                                 H5Dclose, "cannot create dataset " + c.name);
    write.attribute(empty.get(), "checksum", H5T_STD_U64LE, H5T_NATIVE_UINT64, &checksum);
    return;
  }
  std::visit(
      [&](const auto& values) {
        write.rows(group, c.name.c_str(), n, file_width(c), values, runs, checksum);
      },
      c.values);
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
  const CheckpointRows& rows = block.rows;
  comm.run_collectively([&] {
    const Writer write(ctx, file.get());
    const hid_t root = file.get();
    const std::int32_t version = checkpoint_format_version, ranks = comm.size();
    const std::string fields = rows.field_list();
    write.string_attribute(root, "format", format_name);
    write.attribute(root, "version", H5T_STD_I32LE, H5T_NATIVE_INT32, &version);
    write.attribute(root, "ranks", H5T_STD_I32LE, H5T_NATIVE_INT32, &ranks);
    write.attribute(root, "n_nodes", H5T_STD_I64LE, H5T_NATIVE_INT64, &header.n_nodes);
    write.attribute(root, "n_tets", H5T_STD_I64LE, H5T_NATIVE_INT64, &header.n_tets);
    write.attribute(root, "n_joints", H5T_STD_I64LE, H5T_NATIVE_INT64, &header.n_joints);
    write.attribute(root, "reference_hash", H5T_STD_U64LE, H5T_NATIVE_UINT64,
                    &header.reference_hash);
    write.string_attribute(root, "fields", fields);
    const std::uint64_t checksum = header_checksum(serialized(header), fields);
    write.attribute(root, "header_checksum", H5T_STD_U64LE, H5T_NATIVE_UINT64, &checksum);
    Handle run = write.group("run", /*track_attribute_order=*/true);
    for (const auto& [name, value] : header.doubles)
      write.attribute(run.get(), name, H5T_IEEE_F64LE, H5T_NATIVE_DOUBLE, &value);
    for (const auto& [name, value] : header.integers)
      write.attribute(run.get(), name, H5T_STD_I64LE, H5T_NATIVE_INT64, &value);
  });

  // Nodes and joints: this rank's block of gids, one hyperslab per dataset.
  const auto write_table = [&](const char* group, const CheckpointTable& table, hsize_t n,
                               Run rows_here) {
    comm.run_collectively([&] {
      const Writer write(ctx, file.get());
      std::vector<Run> runs;
      if (rows_here.count > 0) runs.push_back(rows_here);
      Handle handle = write.group(group);
      const std::string prefix = std::string("/") + group + "/";
      write.rows(handle.get(), "gid", n, 0, table.gid, runs, block.checksums.at(prefix + "gid"));
      for (const CheckpointColumn& c : table.columns)
        write_column(ctx, write, handle.get(), c, n, runs, block.checksums.at(prefix + c.name));
    });
  };
  write_table("nodes", rows.nodes, static_cast<hsize_t>(header.n_nodes), block.nodes);
  write_table("joints", rows.joints, static_cast<hsize_t>(header.n_joints), block.joints);

  // Friction pairs: this rank's rows after those of the lower ranks.
  comm.run_collectively([&] {
    const Writer write(ctx, file.get());
    const hsize_t offset = block.friction_offset, total = block.friction_total;
    std::vector<Run> runs;
    if (!rows.pair_a.empty()) runs.push_back({offset, rows.pair_a.size()});
    Handle friction = write.group("friction");
    write.rows(friction.get(), "a", total, 0, rows.pair_a, runs, block.checksums.at("/friction/a"));
    write.rows(friction.get(), "b", total, 0, rows.pair_b, runs, block.checksums.at("/friction/b"));
    for (const CheckpointColumn& c : rows.pair_columns)
      write_column(ctx, write, friction.get(), c, total, runs,
                   block.checksums.at("/friction/" + c.name));
  });

  std::vector<FileRegion> regions;
  comm.run_collectively([&] { regions = data_regions(ctx, file.get(), block); });
  // Flush to storage (MPI_File_sync), then close: only a complete file gets the final name.
  comm.run_collectively([&] {
    ctx.check_collective_write(H5Fflush(file.get(), H5F_SCOPE_GLOBAL),
                               "cannot flush '" + tmp_path + "'");
    ctx.check_collective_write(file.close(), "cannot close '" + tmp_path + "'");
  });
  return regions;
}

// Bytes per row of a group's datasets (its gid included).
double row_bytes(const std::vector<CheckpointColumn>& columns, double keys) {
  double bytes = 8.0 * keys;
  for (const CheckpointColumn& c : columns)
    bytes += double(c.components) *
             std::visit([](const auto& v) { return double(sizeof(v[0])); }, c.values);
  return bytes;
}

// The file's size, about: its datasets and 1 MiB for metadata.
double estimated_file_bytes(const CheckpointHeader& header, const CheckpointRows& rows,
                            std::int64_t friction_pairs) {
  return double(header.n_nodes) * row_bytes(rows.nodes.columns, 1) +
         double(header.n_joints) * row_bytes(rows.joints.columns, 1) +
         double(friction_pairs) * row_bytes(rows.pair_columns, 2) + 1048576.0;
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
  const std::string root_fields = comm.broadcast(owned.field_list(), 0);
  comm.run_collectively([&] {
    FDEM_VERIFY(root_header == serialized(header),
                "checkpoint header differs between rank 0 and rank " + std::to_string(comm.rank()));
    FDEM_VERIFY(
        root_fields == owned.field_list(),
        "checkpoint datasets differ between rank 0 and rank " + std::to_string(comm.rank()));
  });
  // Rows to the ranks of their file blocks; the block ranks see whether every gid arrived once.
  const BlockExchange node_exchange(comm, owned.nodes.gid, header.n_nodes, "node");
  const BlockExchange joint_exchange(comm, owned.joints.gid, header.n_joints, "joint");
  comm.run_collectively([&] {
    FDEM_VERIFY(node_exchange.problem().empty(), "checkpoint rows: " + node_exchange.problem());
    FDEM_VERIFY(joint_exchange.problem().empty(), "checkpoint rows: " + joint_exchange.problem());
  });
  FileBlock block;
  block.nodes = node_exchange.block();
  block.joints = joint_exchange.block();
  CheckpointRows& rows = block.rows;
  const auto to_block = [](const BlockExchange& exchange, const CheckpointTable& from, Run run,
                           CheckpointTable& to) {
    to.gid.resize(run.count);
    std::iota(to.gid.begin(), to.gid.end(), GlobalId(run.start));
    for (const CheckpointColumn& c : from.columns)
      to.columns.push_back(
          c.with_values([&](const auto& v) { return exchange.to_block(v, c.components); }));
  };
  to_block(node_exchange, owned.nodes, block.nodes, rows.nodes);
  to_block(joint_exchange, owned.joints, block.joints, rows.joints);
  rows.pair_a = owned.pair_a;
  rows.pair_b = owned.pair_b;
  rows.pair_columns = owned.pair_columns;
  const std::vector<std::int64_t> pair_counts =
      comm.allgather(static_cast<std::int64_t>(rows.pair_a.size()));
  for (int r = 0; r < comm.size(); ++r) {
    if (r < comm.rank()) block.friction_offset += static_cast<hsize_t>(pair_counts[r]);
    block.friction_total += static_cast<hsize_t>(pair_counts[r]);
  }
  compute_checksums(comm, block);

  // 2. The file under its temporary name, its space claimed first.  A failure is collective:
  //    every rank unwinds (closing the file together) and rank 0 removes the partial file.
  comm.run_collectively([&] {
    if (comm.is_root())
      reserve_space(
          ctx, tmp_path,
          estimated_file_bytes(header, owned, static_cast<std::int64_t>(block.friction_total)));
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

// ---------------------------------------------------------------------------------------------
std::string CheckpointColumn::description() const {
  return name + ":" + value_type_name(type()) + "[" + std::to_string(components) + "]";
}

const CheckpointColumn& CheckpointTable::column(const std::string& name) const {
  for (const CheckpointColumn& c : columns)
    if (c.name == name) return c;
  FDEM_VERIFY(false, "checkpoint rows have a column '" + name + "'");
  return columns.front();
}

std::string CheckpointRows::field_list() const {
  std::string text;
  const auto add = [&](const char* group, const std::vector<CheckpointColumn>& list) {
    for (const CheckpointColumn& c : list)
      text += (text.empty() ? "" : " ") + std::string(group) + "/" + c.description();
  };
  add("nodes", nodes.columns);
  add("joints", joints.columns);
  add("friction", pair_columns);
  return text;
}

}  // namespace fdem
