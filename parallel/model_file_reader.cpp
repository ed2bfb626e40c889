#include "parallel/model_file_reader.hpp"

#include <array>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <type_traits>

#include "core/error.hpp"
#include "parallel/checkpoint_checksum.hpp"
#include "parallel/checkpoint_seal.hpp"

namespace fdem {

using namespace hdf5;

namespace model_file {

namespace {

constexpr DatasetInfo all_datasets[] = {node_tag,           node_x,
                                        tet_nodes,          tet_tag,
                                        tet_entity,         tet_physical,
                                        physical_volumes,   physical_names,
                                        unsupported_entity, unsupported_messages};

std::string shape_text(const std::vector<hsize_t>& dims) {
  std::string text;
  for (std::size_t i = 0; i < dims.size(); ++i) text += (i ? " x " : "") + std::to_string(dims[i]);
  return dims.empty() ? "scalar" : text;
}

bool is_float(DatasetInfo info) {
  return std::strcmp(info.name, node_x.name) == 0;
}

Handle attribute(const Context& ctx, hid_t object, const char* name) {
  const htri_t exists = H5Aexists(object, name);
  if (exists < 0) ctx.fail_hdf5(std::string("cannot look up attribute '") + name + "'");
  if (exists == 0) ctx.fail(std::string("has no root attribute '") + name + "'");
  return ctx.own(H5Aopen(object, name, H5P_DEFAULT), H5Aclose,
                 std::string("cannot open attribute '") + name + "'");
}

std::string text_attribute(const Context& ctx, hid_t object, const char* name) {
  Handle attr = attribute(ctx, object, name);
  Handle type = ctx.own(H5Aget_type(attr.get()), H5Tclose, "cannot get a type");
  if (H5Tget_class(type.get()) != H5T_STRING || H5Tis_variable_str(type.get()) != 0)
    ctx.fail(std::string("root attribute '") + name + "' is not a fixed-length string");
  const std::size_t size = H5Tget_size(type.get());
  std::vector<char> text(size + 1, '\0');
  ctx.check_status(H5Aread(attr.get(), type.get(), text.data()),
                   std::string("cannot read attribute '") + name + "'");
  return std::string(text.data(), strnlen(text.data(), size));
}

template <class T>
T number_attribute(const Context& ctx, hid_t object, const char* name) {
  Handle attr = attribute(ctx, object, name);
  Handle type = ctx.own(H5Aget_type(attr.get()), H5Tclose, "cannot get a type");
  Handle space = ctx.own(H5Aget_space(attr.get()), H5Sclose, "cannot get a shape");
  const bool integral = std::is_integral_v<T>;
  if (H5Tget_class(type.get()) != (integral ? H5T_INTEGER : H5T_FLOAT) ||
      H5Sget_simple_extent_npoints(space.get()) != 1)
    ctx.fail(std::string("attribute '") + name + "' is not " +
             (integral ? "an integer" : "a floating-point number"));
  T value{};
  ctx.check_status(H5Aread(attr.get(), native_type<T>(), &value),
                   std::string("cannot read attribute '") + name + "'");
  return value;
}

// Whether every link of `path` ("/a/b") exists.
bool exists(const Context& ctx, hid_t file, const std::string& path) {
  for (std::size_t slash = path.find('/', 1);; slash = path.find('/', slash + 1)) {
    const std::string prefix = path.substr(0, slash);
    const htri_t found = H5Lexists(file, prefix.c_str(), H5P_DEFAULT);
    if (found < 0) ctx.fail_hdf5("cannot look up " + prefix);
    if (found == 0) return false;
    if (slash == std::string::npos) return true;
  }
}

}  // namespace

Reader::Reader(const std::string& path, const Communicator* comm)
    : ctx_(path, "model file", Context::Mode::read), comm_(comm) {
  const bool root = !comm_ || comm_->is_root();
  SealState sealed = SealState::absent;
  step([&] {
    std::error_code error;
    if (!std::filesystem::exists(path, error)) ctx_.fail("file does not exist");
    if (!std::filesystem::is_regular_file(path, error)) ctx_.fail("is not a regular file");
    // The seal first: damaged metadata must not reach HDF5's parser.
    std::string problem;
    if (root) sealed = check_checkpoint_seal(path, problem);
    if (sealed == SealState::damaged)
      ctx_.fail(problem + ": the file is damaged; prepare it again (fdem prepare)");
    const htri_t is_hdf5 = H5Fis_hdf5(path.c_str());
    if (is_hdf5 < 0) ctx_.fail_hdf5("cannot be opened");
    if (is_hdf5 == 0) ctx_.fail("is not an HDF5 file, so not an fdem model file");
  });
  step([&] {
    Handle fapl;
    if (comm_) {
      fapl = make_mpio_access(ctx_, *comm_);
    } else {
      fapl = make_plist(ctx_, H5P_FILE_ACCESS);
      ctx_.check_status(H5Pset_fclose_degree(fapl.get(), H5F_CLOSE_STRONG),
                        "cannot set close degree");
    }
    file_ = ctx_.own(H5Fopen(path.c_str(), H5F_ACC_RDONLY, fapl.get()), H5Fclose,
                     "cannot open the HDF5 file (damaged or truncated?)");
  });
  step([&] {
    const hid_t file = file_.get();
    const htri_t has_format = H5Aexists(file, "format");
    if (has_format < 0) ctx_.fail_hdf5("cannot read the root attributes");
    const std::string format = has_format ? text_attribute(ctx_, file, "format") : "";
    if (format != model_file_format)
      ctx_.fail(std::string("is an HDF5 file but not an fdem model file (root attribute format ") +
                (has_format ? "is '" + format + "'" : "is missing") + ", expected '" +
                model_file_format + "'); make one with: fdem prepare MESH.msh -o MODEL.h5");
    header_.version = number_attribute<std::int32_t>(ctx_, file, "version");
    if (header_.version != model_file_version)
      ctx_.fail("has format version " + std::to_string(header_.version) +
                "; this fdem reads version " + std::to_string(model_file_version) +
                ": prepare it again with this fdem");
    if (root && sealed != SealState::intact)
      ctx_.fail(
          "its checksum block (the HDF5 userblock) is missing: it was not written by fdem "
          "prepare, or was rewritten since; prepare it again");
    header_.n_nodes = number_attribute<std::int64_t>(ctx_, file, "n_nodes");
    header_.n_tets = number_attribute<std::int64_t>(ctx_, file, "n_tets");
    header_.source = text_attribute(ctx_, file, "source");
    header_.source_bytes = number_attribute<std::int64_t>(ctx_, file, "source_bytes");
    header_.source_mtime_ns = number_attribute<std::int64_t>(ctx_, file, "source_mtime_ns");
    if (number_attribute<std::uint64_t>(ctx_, file, "header_checksum") != header_checksum(header_))
      ctx_.fail(
          "its root attributes do not match their checksum: the file is damaged; prepare it "
          "again");
    if (header_.n_nodes < 0 || header_.n_tets < 0) ctx_.fail("has a negative count");
  });
  step([&] {
    for (const DatasetInfo& info : all_datasets) {
      if (!exists(ctx_, file_.get(), info.name))
        ctx_.fail(std::string("has no dataset ") + info.name + "; the file is damaged");
      Handle d = ctx_.own(H5Dopen2(file_.get(), info.name, H5P_DEFAULT), H5Dclose,
                          std::string("cannot open dataset ") + info.name);
      Handle space = ctx_.own(H5Dget_space(d.get()), H5Sclose, "cannot get a shape");
      const int rank = H5Sget_simple_extent_ndims(space.get());
      std::vector<hsize_t> dims(static_cast<std::size_t>(std::max(rank, 0)));
      if (rank < 0 ||
          (rank > 0 && H5Sget_simple_extent_dims(space.get(), dims.data(), nullptr) < 0))
        ctx_.fail_hdf5(std::string("cannot get the shape of ") + info.name);
      const bool nodes = std::strncmp(info.name, "/nodes/", 7) == 0;
      const bool tets = std::strncmp(info.name, "/tets/", 6) == 0;
      std::vector<hsize_t> expected{nodes          ? static_cast<hsize_t>(header_.n_nodes)
                                    : tets         ? static_cast<hsize_t>(header_.n_tets)
                                    : dims.empty() ? 0
                                                   : dims[0]};
      if (info.width > 0) expected.push_back(static_cast<hsize_t>(info.width));
      if (dims != expected)
        ctx_.fail(std::string("dataset ") + info.name + " has shape " + shape_text(dims) +
                  ", expected " + shape_text(expected) + " (the header says " +
                  std::to_string(header_.n_nodes) + " nodes, " + std::to_string(header_.n_tets) +
                  " tets): the file is truncated or damaged; prepare it again");
      Handle type = ctx_.own(H5Dget_type(d.get()), H5Tclose, "cannot get a type");
      if (H5Tget_class(type.get()) != (is_float(info) ? H5T_FLOAT : H5T_INTEGER))
        ctx_.fail(std::string("dataset ") + info.name + " has the wrong type");
      checksums_.emplace_back(info.name,
                              number_attribute<std::uint64_t>(ctx_, d.get(), "checksum"));
      datasets_.emplace_back(info.name, std::move(d));
    }
  });
  step([&] {
    TableRows rows;
    const auto whole = [&](DatasetInfo info, auto& values) {
      using T = typename std::decay_t<decltype(values)>::value_type;
      const std::size_t width = info.width > 0 ? static_cast<std::size_t>(info.width) : 1;
      Handle space = ctx_.own(H5Dget_space(dataset(info)), H5Sclose, "cannot get a shape");
      const hssize_t points = H5Sget_simple_extent_npoints(space.get());
      values = this->rows<T>(info, 0, static_cast<std::int64_t>(points) / std::int64_t(width));
      if (rows_checksum(info.name, values, width, 0) != stored_checksum(info)) corrupt(info);
    };
    whole(physical_volumes, rows.volumes);
    whole(physical_names, rows.names);
    whole(unsupported_entity, rows.unsupported_entity);
    whole(unsupported_messages, rows.unsupported_messages);
    tables_.n_nodes = header_.n_nodes;
    tables_.n_tets = header_.n_tets;
    if (!tables_from_rows(rows, tables_)) ctx_.fail("its physical-group tables do not parse");
  });
}

Reader::~Reader() {
  datasets_.clear();
  file_.reset();
}

std::string Reader::label() const {
  return "model file '" + ctx_.path() + "' (prepared from '" + header_.source + "')";
}

hid_t Reader::dataset(DatasetInfo info) const {
  for (const auto& [name, handle] : datasets_)
    if (name == info.name) return handle.get();
  FDEM_VERIFY(false, std::string("model file dataset ") + info.name + " opened");
  return -1;
}

std::uint64_t Reader::stored_checksum(DatasetInfo info) const {
  for (const auto& [name, value] : checksums_)
    if (name == info.name) return value;
  FDEM_VERIFY(false, std::string("model file dataset ") + info.name + " has a checksum");
  return 0;
}

void Reader::corrupt(DatasetInfo info) const {
  ctx_.fail(std::string("dataset ") + info.name +
            " does not match its checksum: the file was changed or damaged after it was "
            "written; prepare it again from '" +
            header_.source + "'");
}

template <class T>
std::vector<T> Reader::rows(DatasetInfo info, std::int64_t first, std::int64_t count) const {
  const std::size_t width = info.width > 0 ? static_cast<std::size_t>(info.width) : 1;
  std::vector<T> values(static_cast<std::size_t>(count) * width);
  if (count <= 0) return values;
  const std::string what = std::string("cannot read rows ") + std::to_string(first) + " to " +
                           std::to_string(first + count - 1) + " of dataset " + info.name;
  const hid_t d = dataset(info);
  Handle file_space = ctx_.own(H5Dget_space(d), H5Sclose, what);
  const std::array<hsize_t, 2> start{static_cast<hsize_t>(first), 0},
      size{static_cast<hsize_t>(count), width};
  ctx_.check_status(H5Sselect_hyperslab(file_space.get(), H5S_SELECT_SET, start.data(), nullptr,
                                        size.data(), nullptr),
                    what);
  Handle memory = make_space(ctx_, {static_cast<hsize_t>(values.size())});
  ctx_.check_status(
      H5Dread(d, native_type<T>(), memory.get(), file_space.get(), H5P_DEFAULT, values.data()),
      what + " (truncated or damaged file?)");
  return values;
}

template std::vector<std::int64_t> Reader::rows(DatasetInfo, std::int64_t, std::int64_t) const;
template std::vector<std::int32_t> Reader::rows(DatasetInfo, std::int64_t, std::int64_t) const;
template std::vector<double> Reader::rows(DatasetInfo, std::int64_t, std::int64_t) const;
template std::vector<std::uint8_t> Reader::rows(DatasetInfo, std::int64_t, std::int64_t) const;

}  // namespace model_file

bool is_hdf5_file(const std::string& path) {
  const SilenceHdf5Errors silence;
  std::error_code error;
  if (!std::filesystem::is_regular_file(path, error)) return false;
  return H5Fis_hdf5(path.c_str()) > 0;
}

ModelFileHeader read_model_file_header(const std::string& path) {
  return model_file::Reader(path, nullptr).header();
}

ModelFileContent read_model_file_content(const std::string& path) {
  using namespace model_file;
  const Reader file(path, nullptr);
  ModelFileContent c;
  c.header = file.header();
  c.tables = file.tables();
  const std::int64_t n = c.header.n_nodes, m = c.header.n_tets;
  const auto load = [&](DatasetInfo info, auto& values, std::int64_t rows) {
    using T = typename std::decay_t<decltype(values)>::value_type;
    values = file.rows<T>(info, 0, rows);
    const std::size_t width = info.width > 0 ? static_cast<std::size_t>(info.width) : 1;
    if (rows_checksum(info.name, values, width, 0) != file.stored_checksum(info))
      file.corrupt(info);
  };
  load(tet_nodes, c.tet_nodes, m);
  load(tet_tag, c.tet_tag, m);
  load(tet_entity, c.tet_entity, m);
  load(tet_physical, c.tet_physical, m);
  load(node_tag, c.node_tag, n);
  load(node_x, c.node_x, n);
  return c;
}

GmshMesh read_model_file(const std::string& path, const std::string& physical) {
  using namespace model_file;
  const Reader file(path, nullptr);
  const std::string label = file.label();
  const GmshSelection selection(file.tables(), physical, label);  // unknown group: first
  const std::int64_t n = file.header().n_nodes, m = file.header().n_tets;
  GmshArrays all;
  all.tet_nodes = file.rows<std::int64_t>(tet_nodes, 0, m);
  all.tet_tags = file.rows<std::int64_t>(tet_tag, 0, m);
  for (std::int64_t t = 0; t < m; ++t)
    for (int c = 0; c < 4; ++c) {
      const std::int64_t row = all.tet_nodes[static_cast<std::size_t>(4 * t + c)];
      if (row < 0 || row >= n)
        throw InputError(
            node_row_message(label, all.tet_tags[static_cast<std::size_t>(t)], t, row, n));
    }
  all.tet_entity = file.rows<std::int32_t>(tet_entity, 0, m);
  all.node_tags = file.rows<std::int64_t>(node_tag, 0, n);
  all.node_xyz = file.rows<double>(node_x, 0, n);
  const std::vector<std::int32_t> physicals = file.rows<std::int32_t>(tet_physical, 0, m);
  if (rows_checksum(tet_nodes.name, all.tet_nodes, 4, 0) != file.stored_checksum(tet_nodes))
    file.corrupt(tet_nodes);
  if (rows_checksum(tet_tag.name, all.tet_tags, 1, 0) != file.stored_checksum(tet_tag))
    file.corrupt(tet_tag);
  if (rows_checksum(tet_entity.name, all.tet_entity, 1, 0) != file.stored_checksum(tet_entity))
    file.corrupt(tet_entity);
  if (rows_checksum(tet_physical.name, physicals, 1, 0) != file.stored_checksum(tet_physical))
    file.corrupt(tet_physical);
  if (rows_checksum(node_tag.name, all.node_tags, 1, 0) != file.stored_checksum(node_tag))
    file.corrupt(node_tag);
  if (rows_checksum(node_x.name, all.node_xyz, 3, 0) != file.stored_checksum(node_x))
    file.corrupt(node_x);
  GmshMesh mesh = select_gmsh(file.tables(), all, physical, label);
  for (std::size_t i = 0; i < mesh.node_tags.size(); ++i)
    for (int k = 0; k < 3; ++k)
      if (!std::isfinite(mesh.coords[3 * i + k]))
        throw InputError(non_finite_node_message(label, mesh.node_tags[i]));
  return mesh;
}

}  // namespace fdem
