#include "parallel/xdmf_output.hpp"

#include <hdf5.h>

#include <cerrno>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <sstream>
#include <unordered_map>

#include "core/error.hpp"
#include "parallel/hdf5_support.hpp"

namespace fdem {

using namespace hdf5;

namespace {

constexpr const char* format_name = "fdem-frame";
constexpr std::int32_t format_version = 1;

std::string trimmed(const std::string& text) {
  const auto first = text.find_first_not_of(" \t");
  if (first == std::string::npos) return "";
  return text.substr(first, text.find_last_not_of(" \t") - first + 1);
}

// Names, types and shapes of the arrays: every rank must write the same datasets.
std::string signature(const std::vector<FrameColumn>& arrays) {
  std::ostringstream out;
  for (const FrameColumn& a : arrays)
    out << a.name << '/' << a.per_cell << '/' << a.components << '/' << static_cast<int>(a.type)
        << ';';
  return out.str();
}

void check_rows(const XdmfFrameRows& rows) {
  const std::size_t local = rows.node_gid.size();
  const auto owned = static_cast<std::size_t>(rows.n_owned);
  FDEM_VERIFY(rows.n_owned >= 0 && owned <= local, "frame: more owned nodes than local nodes");
  FDEM_VERIFY(rows.node_x.size() == 3 * owned, "frame: node_x is not 3 values per owned node");
  FDEM_VERIFY(rows.tet_nodes.size() % 4 == 0, "frame: tet_nodes is not 4 nodes per tet");
  for (const LocalIndex n : rows.tet_nodes) {
    FDEM_VERIFY(n >= 0 && static_cast<std::size_t>(n) < local, "frame: a tet node is not local");
    FDEM_VERIFY(
        static_cast<std::size_t>(n) < owned || static_cast<std::size_t>(n) < rows.node_owner.size(),
        "frame: a ghost node without its owner");
  }
  const std::size_t cells = rows.tet_nodes.size() / 4;
  for (const FrameColumn& a : rows.arrays) {
    FDEM_VERIFY(!a.name.empty() && a.name.find('/') == std::string::npos && a.name != "." &&
                    a.name != (a.per_cell ? "connectivity" : "xyz"),
                "frame array name '" + a.name + "' is empty, has a '/' or is reserved");
    FDEM_VERIFY(a.components >= 1 && a.rows == (a.per_cell ? cells : owned),
                "frame array '" + a.name + "' does not have its values for every row");
  }
}

// Node row of every local node the written tets use: owned ones are rows of this rank, a ghost's
// row comes from its owner.  Collective (two personalised exchanges with the ghosts' owners).
std::vector<std::int64_t> connectivity_rows(const Communicator& comm, const XdmfFrameRows& rows,
                                            std::int64_t node_offset, std::string& problem) {
  const auto local = rows.node_gid.size();
  std::vector<std::int64_t> row(local, -1);
  for (LocalIndex n = 0; n < rows.n_owned; ++n) row[static_cast<std::size_t>(n)] = node_offset + n;

  std::vector<std::vector<GlobalId>> request(static_cast<std::size_t>(comm.size()));
  std::vector<std::vector<LocalIndex>> asked_for(request.size());
  std::vector<std::uint8_t> requested(local, 0);
  for (const LocalIndex n : rows.tet_nodes) {
    const auto i = static_cast<std::size_t>(n);
    if (n < rows.n_owned || requested[i]) continue;
    requested[i] = 1;
    const std::int32_t owner = rows.node_owner[i];
    if (owner < 0 || owner >= comm.size() || owner == comm.rank()) {
      problem = "ghost node gid " + std::to_string(rows.node_gid[i]) + " has owner rank " +
                std::to_string(owner);
      continue;
    }
    request[static_cast<std::size_t>(owner)].push_back(rows.node_gid[i]);
    asked_for[static_cast<std::size_t>(owner)].push_back(n);
  }
  std::vector<int> sources;
  const std::vector<GlobalId> asked = comm.exchange(request, &sources);

  std::unordered_map<GlobalId, LocalIndex> owned_index;
  owned_index.reserve(static_cast<std::size_t>(rows.n_owned));
  for (LocalIndex n = 0; n < rows.n_owned; ++n) owned_index.emplace(rows.node_gid[n], n);
  std::vector<std::vector<std::int64_t>> answer(request.size());
  for (std::size_t k = 0; k < asked.size(); ++k) {
    const auto it = owned_index.find(asked[k]);
    answer[static_cast<std::size_t>(sources[k])].push_back(
        it == owned_index.end() ? -1 : node_offset + it->second);
  }
  // Answers come back in rank order, each rank's in the order of the requests sent to it.
  const std::vector<std::int64_t> answered = comm.exchange(answer);
  std::size_t k = 0;
  for (const auto& nodes : asked_for)
    for (const LocalIndex n : nodes) {
      row[static_cast<std::size_t>(n)] = answered[k++];
      if (row[static_cast<std::size_t>(n)] < 0 && problem.empty())
        problem = "ghost node gid " + std::to_string(rows.node_gid[static_cast<std::size_t>(n)]) +
                  " is not owned by rank " +
                  std::to_string(rows.node_owner[static_cast<std::size_t>(n)]);
    }
  return row;
}

// MPI_Info of the hints (freed at scope exit; HDF5 keeps its own copy).
class InfoObject {
 public:
  explicit InfoObject(const MpiIoHints& hints) {
    if (hints.empty()) return;
    MPI_Info_create(&info_);
    for (const auto& [key, value] : hints) MPI_Info_set(info_, key.c_str(), value.c_str());
  }
  ~InfoObject() {
    if (info_ != MPI_INFO_NULL) MPI_Info_free(&info_);
  }
  InfoObject(const InfoObject&) = delete;
  InfoObject& operator=(const InfoObject&) = delete;
  MPI_Info get() const { return info_; }

 private:
  MPI_Info info_ = MPI_INFO_NULL;
};

struct Layout {
  std::int64_t node_offset = 0, tet_offset = 0, n_nodes = 0, n_tets = 0;
};

void write_array(const Writer& write, hid_t group, const FrameArray& a, hsize_t n_rows,
                 const std::vector<Run>& runs) {
  const hsize_t width = a.components == 1 ? 0 : static_cast<hsize_t>(a.components);
  if (a.type == FrameValue::f64)
    return write.rows(group, a.name.c_str(), n_rows, width, a.real, runs);
  if (a.type == FrameValue::i64)
    return write.rows(group, a.name.c_str(), n_rows, width, a.integer, runs);
  const std::vector<std::int32_t> narrow(a.integer.begin(), a.integer.end());
  write.rows(group, a.name.c_str(), n_rows, width, narrow, runs);
}

void write_file(const Context& ctx, const std::string& tmp_path, double time,
                const Communicator& comm, const MpiIoHints& hints, const Layout& layout,
                const XdmfFrameRows& rows, const std::vector<std::int64_t>& connectivity) {
  Handle file;
  comm.run_collectively([&] {
    const InfoObject info(hints);
    Handle fapl = make_mpio_access(ctx, comm, info.get());
    file = ctx.own(H5Fcreate(tmp_path.c_str(), H5F_ACC_TRUNC, H5P_DEFAULT, fapl.get()), H5Fclose,
                   "cannot create '" + tmp_path + "'");
  });
  comm.run_collectively([&] {
    const Writer write(ctx, file.get());
    const hid_t root = file.get();
    const std::int32_t ranks = comm.size();
    write.string_attribute(root, "format", format_name);
    write.attribute(root, "version", H5T_STD_I32LE, H5T_NATIVE_INT32, &format_version);
    write.attribute(root, "time", H5T_IEEE_F64LE, H5T_NATIVE_DOUBLE, &time);
    write.attribute(root, "ranks", H5T_STD_I32LE, H5T_NATIVE_INT32, &ranks);
    write.attribute(root, "n_nodes", H5T_STD_I64LE, H5T_NATIVE_INT64, &layout.n_nodes);
    write.attribute(root, "n_tets", H5T_STD_I64LE, H5T_NATIVE_INT64, &layout.n_tets);
  });
  // Each rank: one run of node rows and one of tet rows (a rank with none takes part empty).
  const auto n_owned = static_cast<hsize_t>(rows.n_owned);
  const hsize_t n_cells = connectivity.size() / 4;
  std::vector<Run> node_runs, tet_runs;
  if (n_owned > 0) node_runs.push_back({static_cast<hsize_t>(layout.node_offset), n_owned});
  if (n_cells > 0) tet_runs.push_back({static_cast<hsize_t>(layout.tet_offset), n_cells});
  comm.run_collectively([&] {
    const Writer write(ctx, file.get());
    const auto n = static_cast<hsize_t>(layout.n_nodes);
    Handle nodes = write.group("nodes");
    write.rows(nodes.get(), "xyz", n, 3, rows.node_x, node_runs);
    for (const FrameColumn& a : rows.arrays)  // one array in memory at a time
      if (!a.per_cell) write_array(write, nodes.get(), a.materialize(), n, node_runs);
  });
  comm.run_collectively([&] {
    const Writer write(ctx, file.get());
    const auto n = static_cast<hsize_t>(layout.n_tets);
    Handle tets = write.group("tets");
    write.rows(tets.get(), "connectivity", n, 4, connectivity, tet_runs);
    for (const FrameColumn& a : rows.arrays)
      if (a.per_cell) write_array(write, tets.get(), a.materialize(), n, tet_runs);
  });
  comm.run_collectively([&] {
    ctx.check_collective_write(H5Fflush(file.get(), H5F_SCOPE_GLOBAL),
                               "cannot flush '" + tmp_path + "'");
    ctx.check_collective_write(file.close(), "cannot close '" + tmp_path + "'");
  });
}

// The file's size, about: its datasets (bytes per row) and 1 MiB for metadata.
double estimated_file_bytes(const Layout& layout, const std::vector<FrameColumn>& arrays) {
  double node_row = 3 * 8, tet_row = 4 * 8;  // xyz, connectivity
  for (const FrameColumn& a : arrays)
    (a.per_cell ? tet_row : node_row) +=
        a.components * (a.type == FrameValue::f64 || a.type == FrameValue::i64 ? 8.0 : 4.0);
  return double(layout.n_nodes) * node_row + double(layout.n_tets) * tet_row + 1048576.0;
}

FrameFileInfo frame_info(const std::string& file, double time, const Layout& layout,
                         const std::vector<FrameColumn>& arrays) {
  using Role = FrameDataset::Role;
  FrameFileInfo info;
  info.file = file;
  info.time = time;
  info.n_nodes = layout.n_nodes;
  info.n_tets = layout.n_tets;
  info.datasets.push_back({Role::geometry, "", "/nodes/xyz", layout.n_nodes, 3, FrameValue::f64});
  info.datasets.push_back(
      {Role::topology, "", "/tets/connectivity", layout.n_tets, 4, FrameValue::i64});
  for (const FrameColumn& a : arrays)
    info.datasets.push_back({a.per_cell ? Role::cell : Role::point, a.name,
                             (a.per_cell ? "/tets/" : "/nodes/") + a.name,
                             a.per_cell ? layout.n_tets : layout.n_nodes, a.components, a.type});
  return info;
}

}  // namespace

Communicator process_communicator() {
  int initialised = 0;
  MPI_Initialized(&initialised);
  if (!initialised)
    throw InputError(
        "output.format xdmf writes its frames with MPI-IO, and MPI is not initialised "
        "here (run the fdem command, or use output.format vtu)");
  return Communicator(MPI_COMM_SELF);
}

MpiIoHints merge_mpi_io_hints(const MpiIoHints& scene, const char* environment) {
  MpiIoHints hints = scene;
  if (!environment) return hints;
  std::stringstream entries(environment);
  for (std::string entry; std::getline(entries, entry, ',');) {
    if (trimmed(entry).empty()) continue;
    const auto eq = entry.find('=');
    const std::string key = eq == std::string::npos ? "" : trimmed(entry.substr(0, eq));
    const std::string value = eq == std::string::npos ? "" : trimmed(entry.substr(eq + 1));
    if (key.empty() || value.empty())
      throw InputError("FDEM_MPIIO_HINTS: '" + entry +
                       "' is not key=value (expected e.g. "
                       "FDEM_MPIIO_HINTS=\"striping_factor=16,romio_cb_write=enable\")");
    const auto same = std::find_if(hints.begin(), hints.end(),
                                   [&](const auto& hint) { return hint.first == key; });
    if (same != hints.end())
      same->second = value;
    else
      hints.emplace_back(key, value);
  }
  return hints;
}

FrameFileInfo write_xdmf_frame(const std::string& directory, const std::string& file, double time,
                               const Communicator& comm, const XdmfFrameRows& rows,
                               const MpiIoHints& hints) {
  const std::string path = (std::filesystem::path(directory) / file).string();
  const std::string tmp_path = path + ".tmp";
  Context ctx(path, "frame", Context::Mode::write);
  ctx.abort_on(comm);

  // 1. The caller's rows, on each rank and across ranks, before any file I/O.
  comm.run_collectively([&] { check_rows(rows); });
  const std::string mine = signature(rows.arrays);
  const std::string root_signature = comm.broadcast(mine, 0);
  comm.run_collectively([&] {
    FDEM_VERIFY(root_signature == mine,
                "frame arrays differ between rank 0 and rank " + std::to_string(comm.rank()));
  });

  // 2. File rows: each rank's block at the exclusive prefix sum of the owned counts.
  Layout layout;
  {
    std::int64_t counts[2] = {rows.n_owned, static_cast<std::int64_t>(rows.tet_nodes.size() / 4)};
    std::int64_t offsets[2] = {0, 0}, totals[2] = {0, 0};
    MPI_Exscan(counts, offsets, 2, MPI_INT64_T, MPI_SUM, comm.handle());
    if (comm.rank() == 0) offsets[0] = offsets[1] = 0;  // MPI_Exscan leaves rank 0's undefined
    MPI_Allreduce(counts, totals, 2, MPI_INT64_T, MPI_SUM, comm.handle());
    layout = {offsets[0], offsets[1], totals[0], totals[1]};
  }
  std::string problem;
  const std::vector<std::int64_t> node_row =
      connectivity_rows(comm, rows, layout.node_offset, problem);
  comm.run_collectively([&] { FDEM_VERIFY(problem.empty(), "frame connectivity: " + problem); });
  std::vector<std::int64_t> connectivity(rows.tet_nodes.size());
  for (std::size_t k = 0; k < connectivity.size(); ++k)
    connectivity[k] = node_row[static_cast<std::size_t>(rows.tet_nodes[k])];

  // 3. The file under its temporary name, its space claimed first (a full disk is then found
  //    where every rank can report it); on a failure every rank unwinds, rank 0 removes it.
  comm.run_collectively([&] {
    if (comm.is_root()) reserve_space(ctx, tmp_path, estimated_file_bytes(layout, rows.arrays));
  });
  {
    const SilenceHdf5Errors silence;
    try {
      write_file(ctx, tmp_path, time, comm, hints, layout, rows, connectivity);
    } catch (const CollectiveFailure&) {
      if (comm.is_root()) std::remove(tmp_path.c_str());
      throw;
    }
  }

  // 4. The final name, by rank 0; every rank waits for it.
  comm.run_collectively([&] {
    if (!comm.is_root()) return;
    if (std::rename(tmp_path.c_str(), path.c_str()) != 0) {
      const std::string reason = std::strerror(errno);
      std::remove(tmp_path.c_str());
      ctx.fail("cannot rename '" + tmp_path + "' to the final name: " + reason);
    }
  });
  return frame_info(file, time, layout, rows.arrays);
}

}  // namespace fdem
