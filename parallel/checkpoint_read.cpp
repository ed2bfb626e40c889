// Reading a checkpoint on any number of ranks (layout in parallel/checkpoint.hpp).  Every rank
// reads one contiguous block of each dataset by hyperslab (collective I/O), the ranks check the
// datasets' checksums together, and the rows travel from the block ranks to the ranks that hold
// them: what a rank reads and receives is its block plus its own rows, never the whole file.
#include <hdf5.h>

#include <algorithm>
#include <array>
#include <filesystem>
#include <numeric>
#include <sstream>
#include <type_traits>
#include <variant>

#include "core/error.hpp"
#include "parallel/checkpoint.hpp"
#include "parallel/checkpoint_checksum.hpp"
#include "parallel/checkpoint_format.hpp"
#include "parallel/checkpoint_seal.hpp"
#include "parallel/hdf5_support.hpp"

namespace fdem {

using namespace hdf5;
using namespace checkpoint_format;

namespace {

// Checksums of the datasets read: this rank's blocks, summed over the ranks before the check.
struct ChecksumTally {
  std::vector<std::string> names;
  std::vector<std::uint64_t> local, stored;
};

class Reader {
 public:
  Reader(const Context& ctx, hid_t file) : ctx_(ctx), file_(file) {
    dxpl_ = make_collective_transfer(ctx);
  }

  Handle attribute(hid_t object, const std::string& object_name, const std::string& name) const {
    const htri_t exists = H5Aexists(object, name.c_str());
    if (exists < 0) ctx_.fail_hdf5("cannot look up attribute '" + name + "' of " + object_name);
    if (exists == 0) ctx_.fail(object_name + " has no attribute '" + name + "'");
    return ctx_.own(H5Aopen(object, name.c_str(), H5P_DEFAULT), H5Aclose,
                    "cannot open attribute '" + name + "' of " + object_name);
  }

  H5T_class_t attribute_class(hid_t attr, const std::string& name) const {
    Handle type = ctx_.own(H5Aget_type(attr), H5Tclose, "cannot get the type of " + name);
    Handle space = ctx_.own(H5Aget_space(attr), H5Sclose, "cannot get the shape of " + name);
    if (H5Sget_simple_extent_npoints(space.get()) != 1)
      ctx_.fail("attribute '" + name + "' is not a single value");
    return H5Tget_class(type.get());
  }

  std::string string_attribute(hid_t object, const std::string& object_name,
                               const std::string& name) const {
    Handle attr = attribute(object, object_name, name);
    if (attribute_class(attr.get(), name) != H5T_STRING)
      ctx_.fail("attribute '" + name + "' of " + object_name + " is not a string");
    Handle type = ctx_.own(H5Aget_type(attr.get()), H5Tclose, "cannot get the type of " + name);
    if (H5Tis_variable_str(type.get()) != 0)
      ctx_.fail("attribute '" + name + "' of " + object_name + " is not a fixed-length string");
    const std::size_t size = H5Tget_size(type.get());
    std::vector<char> text(size + 1, '\0');
    ctx_.check_status(H5Aread(attr.get(), type.get(), text.data()), "cannot read " + name);
    return std::string(text.data(), strnlen(text.data(), size));
  }

  template <class T>
  T number_attribute(hid_t object, const std::string& object_name, const std::string& name) const {
    Handle attr = attribute(object, object_name, name);
    const H5T_class_t cls = attribute_class(attr.get(), name);
    const bool integral = std::is_integral_v<T>;
    if (cls != (integral ? H5T_INTEGER : H5T_FLOAT))
      ctx_.fail("attribute '" + name + "' of " + object_name + " is not " +
                (integral ? "an integer" : "a floating-point number"));
    T value{};
    ctx_.check_status(H5Aread(attr.get(), native_type<T>(), &value),
                      "cannot read attribute '" + name + "' of " + object_name);
    return value;
  }

  Handle group(const char* name) const {
    const htri_t exists = H5Lexists(file_, name, H5P_DEFAULT);
    if (exists < 0) ctx_.fail_hdf5(std::string("cannot look up group ") + name);
    if (exists == 0) ctx_.fail(std::string("has no group ") + name);
    return ctx_.own(H5Gopen2(file_, name, H5P_DEFAULT), H5Gclose,
                    std::string("cannot open group ") + name);
  }

  // Names of the attributes of `object`, in creation order.
  std::vector<std::string> attribute_names(hid_t object, const std::string& object_name) const {
    std::vector<std::string> names;
    hsize_t index = 0;
    auto collect = [](hid_t, const char* name, const H5A_info_t*, void* out) -> herr_t {
      static_cast<std::vector<std::string>*>(out)->emplace_back(name);
      return 0;
    };
    ctx_.check_status(H5Aiterate2(object, H5_INDEX_CRT_ORDER, H5_ITER_INC, &index, collect, &names),
                      "cannot list the values of " + object_name);
    return names;
  }

  // Rows `rows` of dataset `group_name/name`, whose shape must be `dims` (explained by `why` in
  // the message) and whose type class matches T, in row-major order; its checksum attribute and
  // this block's share of the checksum go to `tally`.  Collective (a rank may read no rows).
  template <class T>
  std::vector<T> block(hid_t group, const std::string& group_name, const char* name,
                       const std::vector<hsize_t>& dims, const std::string& why, Run rows,
                       ChecksumTally& tally) const {
    const std::string full = group_name + "/" + name;
    const htri_t exists = H5Lexists(group, name, H5P_DEFAULT);
    if (exists < 0) ctx_.fail_hdf5("cannot look up dataset " + full);
    if (exists == 0) ctx_.fail("has no dataset " + full);
    Handle dataset = ctx_.own(H5Dopen2(group, name, H5P_DEFAULT), H5Dclose, "cannot open " + full);
    Handle space =
        ctx_.own(H5Dget_space(dataset.get()), H5Sclose, "cannot get the shape of " + full);
    const int rank = H5Sget_simple_extent_ndims(space.get());
    if (rank < 0) ctx_.fail_hdf5("cannot get the shape of " + full);
    std::vector<hsize_t> found(static_cast<std::size_t>(rank));
    if (rank > 0 && H5Sget_simple_extent_dims(space.get(), found.data(), nullptr) < 0)
      ctx_.fail_hdf5("cannot get the shape of " + full);
    if (found != dims)
      ctx_.fail("dataset " + full + " has shape " + shape_text(found) + ", expected " +
                shape_text(dims) + " (" + why + ")");
    Handle type = ctx_.own(H5Dget_type(dataset.get()), H5Tclose, "cannot get the type of " + full);
    const H5T_class_t cls = H5Tget_class(type.get());
    const H5T_class_t wanted = std::is_floating_point_v<T> ? H5T_FLOAT : H5T_INTEGER;
    if (cls != wanted)
      ctx_.fail("dataset " + full + " is not of " +
                (wanted == H5T_FLOAT ? "floating-point" : "integer") + " type");
    const hsize_t width = dims.size() > 1 ? dims[1] : 1;
    std::vector<T> values(static_cast<std::size_t>(rows.count * width));
    hsize_t total = 1;
    for (hsize_t d : dims) total *= d;
    if (total > 0) {  // the same on every rank: a rank without rows still joins the read
      const std::array<hsize_t, 2> start{rows.start, 0}, count{rows.count, width};
      if (rows.count > 0)
        ctx_.check_status(H5Sselect_hyperslab(space.get(), H5S_SELECT_SET, start.data(), nullptr,
                                              count.data(), nullptr),
                          "cannot select rows of " + full);
      else
        ctx_.check_status(H5Sselect_none(space.get()), "cannot select in " + full);
      Handle memory = make_space(ctx_, {std::max<hsize_t>(rows.count * width, 1)});
      if (rows.count == 0)
        ctx_.check_status(H5Sselect_none(memory.get()), "cannot select in " + full);
      T dummy{};
      ctx_.check_status(H5Dread(dataset.get(), native_type<T>(), memory.get(), space.get(),
                                dxpl_.get(), values.empty() ? &dummy : values.data()),
                        "cannot read " + full);
    }
    tally.names.push_back(full);
    tally.stored.push_back(number_attribute<std::uint64_t>(dataset.get(), full, "checksum"));
    tally.local.push_back(rows_checksum(full, values, static_cast<std::size_t>(width), rows.start));
    return values;
  }

 private:
  static std::string shape_text(const std::vector<hsize_t>& dims) {
    if (dims.empty()) return "scalar";
    std::string text;
    for (std::size_t i = 0; i < dims.size(); ++i)
      text += (i ? " x " : "") + std::to_string(dims[i]);
    return text;
  }

  const Context& ctx_;
  hid_t file_;
  Handle dxpl_;
};

Run block_of(const GidBlocks& blocks, int rank) {
  return {static_cast<hsize_t>(blocks.begin(rank)), static_cast<hsize_t>(blocks.count(rank))};
}

// The gid column of a block must hold start, start + 1, ...
void check_dense_gids(const Context& ctx, const std::vector<GlobalId>& gids, Run rows,
                      const char* what) {
  for (std::size_t i = 0; i < gids.size(); ++i)
    if (gids[i] != static_cast<GlobalId>(rows.start + i))
      ctx.fail(std::string("dataset ") + what + " holds gid " + std::to_string(gids[i]) +
               " in row " + std::to_string(rows.start + i) +
               "; a checkpoint stores gid i in row i");
}

// Rows wanted by gid from the ranks whose blocks hold them.  The requests travel once; each
// `fetch` then moves one array.  Received rows come in rank order, so ascending wanted gids come
// back ascending.
class BlockFetch {
 public:
  // Collective.  `wanted` ascending, each in 0..blocks.n-1 (checked by the caller).
  BlockFetch(const Communicator& comm, const GidBlocks& blocks, const std::vector<GlobalId>& wanted)
      : comm_(comm), block_start_(blocks.begin(comm.rank())) {
    std::vector<std::vector<GlobalId>> requests(static_cast<std::size_t>(comm.size()));
    for (GlobalId g : wanted) requests[static_cast<std::size_t>(blocks.owner(g))].push_back(g);
    asked_ = comm.exchange(requests, &askers_);
  }

  // The rows of `block` (this rank's block, `width` values per row) that each rank asked for.
  template <class T>
  std::vector<T> fetch(const std::vector<T>& block, std::size_t width) const {
    std::vector<std::vector<T>> replies(static_cast<std::size_t>(comm_.size()));
    for (std::size_t k = 0; k < asked_.size(); ++k) {
      const auto row = static_cast<std::size_t>(asked_[k] - block_start_);
      auto& reply = replies[static_cast<std::size_t>(askers_[k])];
      reply.insert(reply.end(), block.begin() + static_cast<std::ptrdiff_t>(row * width),
                   block.begin() + static_cast<std::ptrdiff_t>((row + 1) * width));
    }
    return comm_.exchange(replies);
  }

 private:
  Communicator comm_;
  std::int64_t block_start_;
  std::vector<GlobalId> asked_;
  std::vector<int> askers_;
};

// A friction pair travels between ranks as the record the contact stage keeps
// (core/travelling_state.hpp): its tets and its values, the pair columns' components in column
// order.
constexpr std::size_t max_pair_values = sizeof(PairRecord::value) / sizeof(double);
using FrictionRow = PairRecord;

bool pair_less(const FrictionRow& p, const FrictionRow& q) {
  return p.a != q.a ? p.a < q.a : p.b < q.b;
}

// The file's friction rows (this rank's slice of them) to the ranks that want their first tet:
// first to the block rank of tet a (blocks of n_tets), then to the askers.  Collective.
std::vector<FrictionRow> deliver_friction(const Communicator& comm, std::int64_t n_tets,
                                          const std::vector<FrictionRow>& slice,
                                          const std::vector<GlobalId>& wanted_tets) {
  const GidBlocks tet_blocks{n_tets, comm.size()};
  std::vector<std::vector<FrictionRow>> to_block(static_cast<std::size_t>(comm.size()));
  for (const FrictionRow& row : slice)
    to_block[static_cast<std::size_t>(tet_blocks.owner(row.a))].push_back(row);
  std::vector<FrictionRow> held = comm.exchange(to_block);
  std::sort(held.begin(), held.end(), pair_less);

  std::vector<std::vector<GlobalId>> requests(static_cast<std::size_t>(comm.size()));
  for (GlobalId g : wanted_tets)
    requests[static_cast<std::size_t>(tet_blocks.owner(g))].push_back(g);
  std::vector<int> askers;
  const std::vector<GlobalId> asked = comm.exchange(requests, &askers);
  std::vector<std::vector<FrictionRow>> replies(static_cast<std::size_t>(comm.size()));
  for (std::size_t k = 0; k < asked.size(); ++k) {
    const auto first = std::lower_bound(held.begin(), held.end(), asked[k],
                                        [](const FrictionRow& r, GlobalId g) { return r.a < g; });
    auto& reply = replies[static_cast<std::size_t>(askers[k])];
    for (auto it = first; it != held.end() && it->a == asked[k]; ++it) reply.push_back(*it);
  }
  std::vector<FrictionRow> mine = comm.exchange(replies);
  std::sort(mine.begin(), mine.end(), pair_less);
  return mine;
}

// The columns a field list ("group/name:type[components]" separated by spaces) names, with no
// rows; an empty string when it is well formed, else what is wrong.
std::string parse_field_list(const std::string& text, CheckpointRows& layout) {
  std::istringstream in(text);
  std::string item;
  while (in >> item) {
    const std::size_t slash = item.find('/'), colon = item.find(':'), open = item.find('['),
                      close = item.find(']');
    if (slash == std::string::npos || colon == std::string::npos || open == std::string::npos ||
        close != item.size() - 1 || !(slash < colon && colon < open))
      return "'" + item + "' is not group/name:type[components]";
    const std::string group = item.substr(0, slash),
                      type = item.substr(colon + 1, open - colon - 1);
    CheckpointColumn column;
    column.name = item.substr(slash + 1, colon - slash - 1);
    const std::string count = item.substr(open + 1, close - open - 1);
    if (count.empty() || count.find_first_not_of("0123456789") != std::string::npos ||
        count.size() > 6)
      return "'" + item + "' has no component count";
    column.components = std::stoul(count);
    if (type == value_type_name(ValueType::f64))
      column.values = std::vector<double>{};
    else if (type == value_type_name(ValueType::i32))
      column.values = std::vector<std::int32_t>{};
    else if (type == value_type_name(ValueType::u8))
      column.values = std::vector<std::uint8_t>{};
    else
      return "'" + item + "' has type '" + type + "' (float64, int32 or uint8)";
    if (group == "nodes")
      layout.nodes.columns.push_back(std::move(column));
    else if (group == "joints")
      layout.joints.columns.push_back(std::move(column));
    else if (group == "friction" && type == value_type_name(ValueType::f64))
      layout.pair_columns.push_back(std::move(column));
    else
      return "'" + item + "' is not in nodes, joints or friction (float64)";
  }
  std::size_t pair_values = 0;
  for (const CheckpointColumn& c : layout.pair_columns) pair_values += c.components;
  if (pair_values > max_pair_values)
    return "friction pairs have " + std::to_string(pair_values) + " values, at most " +
           std::to_string(max_pair_values);
  return {};
}

// `wanted` must be ascending, without repeats, within 0..n-1.
void check_wanted(const Context& ctx, const std::vector<GlobalId>& wanted, std::int64_t n,
                  const char* what) {
  for (std::size_t i = 0; i < wanted.size(); ++i)
    if (wanted[i] < 0 || wanted[i] >= n || (i > 0 && wanted[i] <= wanted[i - 1]))
      ctx.fail(std::string("holds ") + std::to_string(n) + " " + what +
               "s; this rank needs the row of " + what + " gid " + std::to_string(wanted[i]) +
               " (written for a different scene?)");
}

std::vector<GlobalId> all_gids(std::int64_t n) {
  std::vector<GlobalId> gids(static_cast<std::size_t>(n));
  std::iota(gids.begin(), gids.end(), GlobalId(0));
  return gids;
}

// The header: format, version, seal, counts and run values.  Collective.
CheckpointHeader read_header(const Context& ctx, const Communicator& comm, hid_t root,
                             SealState sealed, std::string& field_list) {
  CheckpointHeader header;
  comm.run_collectively([&] {
    const Reader read(ctx, root);
    const htri_t has_format = H5Aexists(root, "format");
    if (has_format < 0) ctx.fail_hdf5("cannot read the root attributes");
    const std::string format = has_format ? read.string_attribute(root, "/", "format") : "";
    if (format != format_name)
      ctx.fail(std::string("is an HDF5 file but not an fdem checkpoint (root attribute format ") +
               (has_format ? "is '" + format + "'" : "is missing") + ", expected '" + format_name +
               "')");
    const auto version = read.number_attribute<std::int32_t>(root, "/", "version");
    if (version != checkpoint_format_version)
      ctx.fail("has format version " + std::to_string(version) + "; this fdem reads version " +
               std::to_string(checkpoint_format_version) +
               (version < checkpoint_format_version
                    ? " (the file was written by an older fdem: continue it with that fdem, or "
                      "run the scene from the start)"
                    : " (the file was written by a newer fdem)"));
    if (comm.is_root() && sealed != SealState::intact)
      ctx.corrupt("its checksum block (the HDF5 userblock) is missing");
    header.ranks = read.number_attribute<std::int32_t>(root, "/", "ranks");
    header.n_nodes = read.number_attribute<std::int64_t>(root, "/", "n_nodes");
    header.n_tets = read.number_attribute<std::int64_t>(root, "/", "n_tets");
    header.n_joints = read.number_attribute<std::int64_t>(root, "/", "n_joints");
    header.reference_hash = read.number_attribute<std::uint64_t>(root, "/", "reference_hash");
    field_list = read.string_attribute(root, "/", "fields");
    if (header.n_nodes < 0 || header.n_tets < 0 || header.n_joints < 0)
      ctx.fail("has a negative count in its root attributes");

    Handle run = read.group("/run");
    for (const std::string& name : read.attribute_names(run.get(), "/run")) {
      Handle attr = read.attribute(run.get(), "/run", name);
      const H5T_class_t cls = read.attribute_class(attr.get(), "/run/" + name);
      attr.reset();
      if (cls == H5T_FLOAT)
        header.doubles.emplace_back(name, read.number_attribute<double>(run.get(), "/run", name));
      else if (cls == H5T_INTEGER)
        header.integers.emplace_back(name,
                                     read.number_attribute<std::int64_t>(run.get(), "/run", name));
      else
        ctx.fail("value /run/" + name + " is neither a floating-point number nor an integer");
    }
    const auto stored = read.number_attribute<std::uint64_t>(root, "/", "header_checksum");
    if (header_checksum(serialized(header), field_list) != stored)
      ctx.corrupt("header (the root attributes and /run values)");
  });
  return header;
}

// What each rank read of the file: its block of every dataset and its slice of friction rows.
struct FileBlocks {
  Run nodes, joints, pairs;
  CheckpointRows rows;  // gids, values of the blocks; friction of the slice
};

// Rows `b` of every column of `layout` in `group` (n rows), into `out`.
void read_columns(const Reader& read, hid_t group, const std::string& group_name,
                  const std::vector<CheckpointColumn>& layout, hsize_t n, const std::string& why,
                  Run b, ChecksumTally& tally, std::vector<CheckpointColumn>& out) {
  for (const CheckpointColumn& c : layout) {
    CheckpointColumn& column = out.emplace_back();
    column.name = c.name;
    column.components = c.components;
    const std::vector<hsize_t> dims =
        c.components == 1 ? std::vector<hsize_t>{n} : std::vector<hsize_t>{n, c.components};
    column.values = std::visit(
        [&](const auto& empty) {
          using T = typename std::decay_t<decltype(empty)>::value_type;
          return CheckpointValues(
              read.template block<T>(group, group_name, c.name.c_str(), dims, why, b, tally));
        },
        c.values);
  }
}

FileBlocks read_blocks(const Context& ctx, const Communicator& comm, hid_t file,
                       const CheckpointHeader& header, const CheckpointRows& layout) {
  FileBlocks blocks;
  CheckpointRows& rows = blocks.rows;
  ChecksumTally tally;
  blocks.nodes = block_of(GidBlocks{header.n_nodes, comm.size()}, comm.rank());
  blocks.joints = block_of(GidBlocks{header.n_joints, comm.size()}, comm.rank());
  const auto read_table = [&](const char* name, std::int64_t count, Run b,
                              const CheckpointTable& wanted, CheckpointTable& out) {
    comm.run_collectively([&] {
      const Reader read(ctx, file);
      const auto n = static_cast<hsize_t>(count);
      const std::string group_name = std::string("/") + name;
      const std::string why = std::string("n_") + name + " = " + std::to_string(n);
      Handle group = read.group(group_name.c_str());
      out.gid = read.block<GlobalId>(group.get(), group_name, "gid", {n}, why, b, tally);
      check_dense_gids(ctx, out.gid, b, (group_name + "/gid").c_str());
      read_columns(read, group.get(), group_name, wanted.columns, n, why, b, tally, out.columns);
    });
  };
  read_table("nodes", header.n_nodes, blocks.nodes, layout.nodes, rows.nodes);
  read_table("joints", header.n_joints, blocks.joints, layout.joints, rows.joints);
  hsize_t pairs = 0;
  comm.run_collectively([&] {
    const Reader read(ctx, file);
    Handle friction = read.group("/friction");
    // The pair count is what /friction/a holds; every other friction dataset must agree.
    Handle a = ctx.own(H5Dopen2(friction.get(), "a", H5P_DEFAULT), H5Dclose,
                       "has no readable dataset /friction/a");
    Handle space = ctx.own(H5Dget_space(a.get()), H5Sclose, "cannot get the shape of /friction/a");
    const hssize_t points = H5Sget_simple_extent_npoints(space.get());
    if (points < 0) ctx.fail_hdf5("cannot get the shape of /friction/a");
    pairs = static_cast<hsize_t>(points);
  });
  blocks.pairs = block_of(GidBlocks{static_cast<std::int64_t>(pairs), comm.size()}, comm.rank());
  comm.run_collectively([&] {
    const Reader read(ctx, file);
    Handle friction = read.group("/friction");
    const std::string why = "/friction/a has " + std::to_string(pairs) + " pairs";
    const Run b = blocks.pairs;
    rows.pair_a = read.block<GlobalId>(friction.get(), "/friction", "a", {pairs}, why, b, tally);
    rows.pair_b = read.block<GlobalId>(friction.get(), "/friction", "b", {pairs}, why, b, tally);
    read_columns(read, friction.get(), "/friction", layout.pair_columns, pairs, why, b, tally,
                 rows.pair_columns);
    for (std::size_t k = 0; k < rows.pair_a.size(); ++k)
      if (rows.pair_a[k] < 0 || rows.pair_a[k] >= rows.pair_b[k] || rows.pair_b[k] >= header.n_tets)
        ctx.fail(
            "dataset /friction/a, /friction/b row " + std::to_string(b.start + k) +
            " is not a pair of tet gids a < b below n_tets = " + std::to_string(header.n_tets));
  });
  // Every rank reached this point (the blocks above are collective failures), so the sum is safe.
  comm.sum_in_place(tally.local);  // unsigned: wraps mod 2^64, the same on any rank count
  comm.run_collectively([&] {
    for (std::size_t i = 0; i < tally.names.size(); ++i)
      if (tally.local[i] != tally.stored[i]) ctx.corrupt("dataset " + tally.names[i]);
  });
  return blocks;
}

// The first difference between two field lists, for the message.
std::string first_difference(const std::string& file, const std::string& here) {
  std::istringstream a(file), b(here);
  std::string x, y;
  while (true) {
    const bool has_x = static_cast<bool>(a >> x), has_y = static_cast<bool>(b >> y);
    if (!has_x && !has_y) return {};
    if (!has_x) return "the file has no dataset " + y;
    if (!has_y) return "the file has a dataset " + x + " this fdem does not restore";
    if (x != y) return "the file has " + x + " where this fdem restores " + y;
  }
}

}  // namespace

std::pair<CheckpointHeader, CheckpointRows> read_checkpoint(
    const std::string& path, const Communicator& comm, const CheckpointWanted* wanted,
    const std::function<void(const CheckpointHeader&)>& check_header,
    const CheckpointRows* layout) {
  const Context ctx(path, "checkpoint", Context::Mode::read);
  const SilenceHdf5Errors silence;

  SealState sealed = SealState::absent;
  comm.run_collectively([&] {
    std::error_code error;
    if (!std::filesystem::exists(path, error)) ctx.fail("file does not exist");
    if (!std::filesystem::is_regular_file(path, error)) ctx.fail("is not a regular file");
    // The seal first (rank 0): damaged metadata must not reach HDF5's parser.
    std::string problem;
    if (comm.is_root()) sealed = check_checkpoint_seal(path, problem);
    if (sealed == SealState::damaged) ctx.corrupt(problem);
    const htri_t is_hdf5 = H5Fis_hdf5(path.c_str());
    if (is_hdf5 < 0) ctx.fail_hdf5("cannot be opened");
    if (is_hdf5 == 0) ctx.fail("is not an HDF5 file, so not an fdem checkpoint");
  });

  Handle file;
  comm.run_collectively([&] {
    Handle fapl = make_mpio_access(ctx, comm);
    file = ctx.own(H5Fopen(path.c_str(), H5F_ACC_RDONLY, fapl.get()), H5Fclose,
                   "cannot open the HDF5 file (damaged or truncated?)");
  });
  std::string field_list;
  CheckpointHeader header = read_header(ctx, comm, file.get(), sealed, field_list);
  if (check_header) comm.run_collectively([&] { check_header(header); });
  CheckpointRows file_layout;
  comm.run_collectively([&] {
    const std::string problem = parse_field_list(field_list, file_layout);
    if (!problem.empty()) ctx.fail("root attribute fields: " + problem);
    if (layout && field_list != layout->field_list())
      ctx.fail("does not hold the datasets this fdem restores (" +
               first_difference(field_list, layout->field_list()) +
               "): it was written by another build of fdem; continue it with that one, or run "
               "the scene from the start");
  });

  CheckpointWanted everything;
  if (!wanted) {
    everything.nodes = all_gids(header.n_nodes);
    everything.joints = all_gids(header.n_joints);
    everything.tets = all_gids(header.n_tets);
    wanted = &everything;
  }
  comm.run_collectively([&] {
    check_wanted(ctx, wanted->nodes, header.n_nodes, "node");
    check_wanted(ctx, wanted->joints, header.n_joints, "joint");
    check_wanted(ctx, wanted->tets, header.n_tets, "tet");
  });
  FileBlocks blocks = read_blocks(ctx, comm, file.get(), header, file_layout);
  comm.run_collectively([&] { ctx.check_status(file.close(), "cannot close the file"); });

  // The block rows to the ranks that want them.
  CheckpointRows rows;
  CheckpointRows& in = blocks.rows;
  const auto fetch = [&](const CheckpointTable& block, std::int64_t n,
                         const std::vector<GlobalId>& gids, CheckpointTable& out) {
    const BlockFetch fetcher(comm, GidBlocks{n, comm.size()}, gids);
    out.gid = gids;
    for (const CheckpointColumn& c : block.columns)
      out.columns.push_back(
          c.with_values([&](const auto& v) { return fetcher.fetch(v, c.components); }));
  };
  fetch(in.nodes, header.n_nodes, wanted->nodes, rows.nodes);
  fetch(in.joints, header.n_joints, wanted->joints, rows.joints);

  std::vector<FrictionRow> slice(in.pair_a.size());
  for (std::size_t k = 0; k < slice.size(); ++k) {
    slice[k].a = in.pair_a[k];
    slice[k].b = in.pair_b[k];
    std::size_t at = 0;
    for (const CheckpointColumn& c : in.pair_columns)
      for (std::size_t i = 0; i < c.components; ++i)
        slice[k].value[at++] = std::get<std::vector<double>>(c.values)[k * c.components + i];
  }
  for (const CheckpointColumn& c : in.pair_columns)
    rows.pair_columns.push_back(
        c.with_values([](const auto& v) { return std::decay_t<decltype(v)>{}; }));
  blocks = FileBlocks{};  // the blocks are no longer needed
  for (const FrictionRow& row : deliver_friction(comm, header.n_tets, slice, wanted->tets)) {
    rows.pair_a.push_back(row.a);
    rows.pair_b.push_back(row.b);
    std::size_t at = 0;
    for (CheckpointColumn& c : rows.pair_columns) {
      auto& values = std::get<std::vector<double>>(c.values);
      values.insert(values.end(), row.value + at, row.value + at + c.components);
      at += c.components;
    }
  }
  return {std::move(header), std::move(rows)};
}

std::pair<CheckpointHeader, CheckpointRows> read_checkpoint(const std::string& path,
                                                            const Communicator& comm) {
  return read_checkpoint(path, comm, nullptr, {}, nullptr);
}

}  // namespace fdem
