// `fdem prepare`: a Gmsh file streamed once into a model file (parallel/model_file.hpp).  One
// process, serial HDF5.  Memory: the parser's window, one block of node rows and one of tet rows,
// the small tables and the node-tag runs — not the mesh.  Nodes go straight to their datasets
// (their count is in the $Nodes header); tets, whose count is known only at the end of
// $Elements, go through a temporary file next to the output, so that every dataset is contiguous
// and of its exact size (the seal, parallel/checkpoint_seal, covers all metadata outside them).
#include <sys/stat.h>

#include <array>
#include <cerrno>
#include <cstdio>
#include <cstring>
#include <memory>

#include "core/error.hpp"
#include "io/gmsh_cursor.hpp"
#include "parallel/checkpoint_seal.hpp"
#include "parallel/hdf5_support.hpp"
#include "parallel/model_file.hpp"
#include "parallel/model_file_layout.hpp"

namespace fdem {

using namespace hdf5;

namespace {

// A tet on its way through the temporary file.
struct SpilledTet {
  std::int64_t nodes[4];
  std::int64_t tag;
  std::int32_t entity, unused;
};

std::vector<hsize_t> dims_of(model_file::DatasetInfo info, std::int64_t rows) {
  std::vector<hsize_t> dims{static_cast<hsize_t>(rows)};
  if (info.width > 0) dims.push_back(static_cast<hsize_t>(info.width));
  return dims;
}

// One contiguous dataset written in blocks of rows, its checksum summed as it goes.
template <class T>
class RowsOut {
 public:
  RowsOut() = default;
  RowsOut(const Context& ctx, hid_t file, model_file::DatasetInfo info, std::int64_t rows)
      : ctx_(&ctx), info_(info), rows_(rows) {
    Handle space = make_space(ctx, dims_of(info, rows));
    Handle dcpl = make_plist(ctx, H5P_DATASET_CREATE);
    ctx.check_status(H5Pset_fill_time(dcpl.get(), H5D_FILL_TIME_NEVER), "cannot set fill time");
    dataset_ = ctx.own(H5Dcreate2(file, info.name, file_type<T>(), space.get(), H5P_DEFAULT,
                                  dcpl.get(), H5P_DEFAULT),
                       H5Dclose, std::string("cannot create dataset ") + info.name);
  }
  bool open() const { return dataset_.valid(); }
  std::int64_t written() const { return next_; }

  // Rows next_, next_ + 1, ... (`values`: width values each); rows past the announced count are
  // dropped (the parser refuses such a file at the end of the section).
  void write(const std::vector<T>& values) {
    const std::size_t width = info_.width > 0 ? static_cast<std::size_t>(info_.width) : 1;
    const auto count =
        std::min<std::int64_t>(static_cast<std::int64_t>(values.size() / width), rows_ - next_);
    if (count <= 0) return;
    const std::string what = std::string("cannot write dataset ") + info_.name;
    Handle file_space = ctx_->own(H5Dget_space(dataset_.get()), H5Sclose, what);
    const std::array<hsize_t, 2> start{static_cast<hsize_t>(next_), 0},
        size{static_cast<hsize_t>(count), width};
    ctx_->check_status(H5Sselect_hyperslab(file_space.get(), H5S_SELECT_SET, start.data(), nullptr,
                                           size.data(), nullptr),
                       what);
    Handle memory = make_space(*ctx_, {static_cast<hsize_t>(count) * width});
    ctx_->check_status(H5Dwrite(dataset_.get(), native_type<T>(), memory.get(), file_space.get(),
                                H5P_DEFAULT, values.data()),
                       what);
    std::vector<T> part(values.begin(), values.begin() + count * static_cast<std::int64_t>(width));
    checksum_ += rows_checksum(info_.name, part, width, static_cast<std::uint64_t>(next_));
    next_ += count;
  }
  // Every row written: the checksum attribute.
  void finish() {
    FDEM_VERIFY(next_ == rows_, std::string("model file dataset ") + info_.name + " incomplete");
    Handle space = make_space(*ctx_, {});
    const std::string what = std::string("cannot write the checksum of ") + info_.name;
    Handle attr = ctx_->own(H5Acreate2(dataset_.get(), "checksum", H5T_STD_U64LE, space.get(),
                                       H5P_DEFAULT, H5P_DEFAULT),
                            H5Aclose, what);
    ctx_->check_status(H5Awrite(attr.get(), H5T_NATIVE_UINT64, &checksum_), what);
  }
  FileRegion region() const {
    const haddr_t address = H5Dget_offset(dataset_.get());
    const hsize_t size = H5Dget_storage_size(dataset_.get());
    return address == HADDR_UNDEF ? FileRegion{} : FileRegion{address, size};
  }
  void close() { dataset_.reset(); }

 private:
  const Context* ctx_ = nullptr;
  model_file::DatasetInfo info_{"", 0};
  std::int64_t rows_ = 0, next_ = 0;
  std::uint64_t checksum_ = 0;
  Handle dataset_;
};

class Spill {
 public:
  Spill(const Context& ctx, std::string path) : ctx_(ctx), path_(std::move(path)) {
    file_ = std::fopen(path_.c_str(), "w+b");
    if (!file_) ctx.fail("cannot create '" + path_ + "': " + std::strerror(errno));
  }
  ~Spill() {
    if (file_) std::fclose(file_);
    std::remove(path_.c_str());
  }
  void write(const std::vector<SpilledTet>& tets) {
    if (!tets.empty() &&
        std::fwrite(tets.data(), sizeof(SpilledTet), tets.size(), file_) != tets.size())
      ctx_.fail("cannot write '" + path_ + "': " + std::strerror(errno));
  }
  void rewind() {
    if (std::fflush(file_) != 0 || std::fseek(file_, 0, SEEK_SET) != 0)
      ctx_.fail("cannot read back '" + path_ + "': " + std::strerror(errno));
  }
  void read(std::vector<SpilledTet>& tets, std::size_t count) {
    tets.resize(count);
    if (count > 0 && std::fread(tets.data(), sizeof(SpilledTet), count, file_) != count)
      ctx_.fail("cannot read back '" + path_ + "'");
  }

 private:
  const Context& ctx_;
  std::string path_;
  std::FILE* file_ = nullptr;
};

class TableWriter final : public GmshSink {
 public:
  TableWriter(const Context& ctx, hid_t file, Spill& spill, std::int64_t block_rows)
      : ctx_(ctx), file_(file), spill_(spill), block_(static_cast<std::size_t>(block_rows)) {}

  void nodes_announced(std::int64_t count) override {
    Handle group = ctx_.own(H5Gcreate2(file_, "/nodes", H5P_DEFAULT, H5P_DEFAULT, H5P_DEFAULT),
                            H5Gclose, "cannot create group /nodes");
    tags_ = RowsOut<std::int64_t>(ctx_, file_, model_file::node_tag, count);
    coords_ = RowsOut<double>(ctx_, file_, model_file::node_x, count);
  }
  void node_tag(std::int64_t, std::int64_t tag) override {
    tag_rows_.push_back(tag);
    if (tag_rows_.size() >= block_) flush_tags();
  }
  void node_coords(std::int64_t, const double (&x)[3]) override {
    xyz_rows_.insert(xyz_rows_.end(), x, x + 3);
    if (xyz_rows_.size() >= 3 * block_) flush_coords();
  }
  void tet(std::int64_t tag, int entity, const std::int64_t (&nodes)[4]) override {
    tets_.push_back({{nodes[0], nodes[1], nodes[2], nodes[3]}, tag, entity, 0});
    if (tets_.size() >= block_) {
      spill_.write(tets_);
      tets_.clear();
    }
  }

  // After the parse: the node datasets completed, the tets copied from the spill, the tables.
  std::vector<FileRegion> finish(const GmshTables& tables) {
    flush_tags();
    flush_coords();
    std::vector<FileRegion> regions;
    tags_.finish();
    coords_.finish();
    regions.push_back(tags_.region());
    regions.push_back(coords_.region());
    tags_.close();
    coords_.close();
    spill_.write(tets_);
    tets_.clear();
    spill_.rewind();

    const std::int64_t m = tables.n_tets;
    Handle group = ctx_.own(H5Gcreate2(file_, "/tets", H5P_DEFAULT, H5P_DEFAULT, H5P_DEFAULT),
                            H5Gclose, "cannot create group /tets");
    RowsOut<std::int64_t> nodes(ctx_, file_, model_file::tet_nodes, m);
    RowsOut<std::int64_t> tags(ctx_, file_, model_file::tet_tag, m);
    RowsOut<std::int32_t> entity(ctx_, file_, model_file::tet_entity, m);
    RowsOut<std::int32_t> physical(ctx_, file_, model_file::tet_physical, m);
    std::vector<SpilledTet> block;
    std::vector<std::int64_t> node_rows, tag_rows;
    std::vector<std::int32_t> entity_rows, physical_rows;
    for (std::int64_t done = 0; done < m;) {
      const auto count = static_cast<std::size_t>(
          std::min<std::int64_t>(static_cast<std::int64_t>(block_), m - done));
      spill_.read(block, count);
      node_rows.clear();
      tag_rows.clear();
      entity_rows.clear();
      physical_rows.clear();
      for (const SpilledTet& t : block) {
        node_rows.insert(node_rows.end(), t.nodes, t.nodes + 4);
        tag_rows.push_back(t.tag);
        entity_rows.push_back(t.entity);
        const auto it = tables.volume_physicals.find(t.entity);
        physical_rows.push_back(
            it != tables.volume_physicals.end() && !it->second.empty() ? it->second[0] : 0);
      }
      nodes.write(node_rows);
      tags.write(tag_rows);
      entity.write(entity_rows);
      physical.write(physical_rows);
      done += static_cast<std::int64_t>(count);
    }
    for (auto* out : {&nodes, &tags}) {
      out->finish();
      regions.push_back(out->region());
    }
    for (auto* out : {&entity, &physical}) {
      out->finish();
      regions.push_back(out->region());
    }

    const model_file::TableRows rows = model_file::table_rows(tables);
    for (const char* name : {"/physical", "/unsupported"})
      ctx_.own(H5Gcreate2(file_, name, H5P_DEFAULT, H5P_DEFAULT, H5P_DEFAULT), H5Gclose,
               std::string("cannot create group ") + name);
    regions.push_back(whole(model_file::physical_volumes, rows.volumes));
    regions.push_back(whole(model_file::physical_names, rows.names));
    regions.push_back(whole(model_file::unsupported_entity, rows.unsupported_entity));
    regions.push_back(whole(model_file::unsupported_messages, rows.unsupported_messages));
    return regions;
  }

 private:
  template <class T>
  FileRegion whole(model_file::DatasetInfo info, const std::vector<T>& values) {
    const std::size_t width = info.width > 0 ? static_cast<std::size_t>(info.width) : 1;
    RowsOut<T> out(ctx_, file_, info, static_cast<std::int64_t>(values.size() / width));
    out.write(values);
    out.finish();
    return out.region();
  }
  void flush_tags() {
    if (tags_.open()) tags_.write(tag_rows_);
    tag_rows_.clear();
  }
  void flush_coords() {
    if (coords_.open()) coords_.write(xyz_rows_);
    xyz_rows_.clear();
  }

  const Context& ctx_;
  hid_t file_;
  Spill& spill_;
  std::size_t block_;
  RowsOut<std::int64_t> tags_;
  RowsOut<double> coords_;
  std::vector<std::int64_t> tag_rows_;
  std::vector<double> xyz_rows_;
  std::vector<SpilledTet> tets_;
};

void write_header(const Context& ctx, hid_t file, const ModelFileHeader& header) {
  const auto attribute = [&](const char* name, hid_t file_type, hid_t memory_type,
                             const void* value) {
    Handle space = make_space(ctx, {});
    Handle attr = ctx.own(H5Acreate2(file, name, file_type, space.get(), H5P_DEFAULT, H5P_DEFAULT),
                          H5Aclose, std::string("cannot create attribute ") + name);
    ctx.check_status(H5Awrite(attr.get(), memory_type, value),
                     std::string("cannot write attribute ") + name);
  };
  const auto text = [&](const char* name, const std::string& value) {
    Handle type = ctx.own(H5Tcopy(H5T_C_S1), H5Tclose, "cannot create a string type");
    ctx.check_status(H5Tset_size(type.get(), value.size() + 1), "cannot size a string type");
    ctx.check_status(H5Tset_strpad(type.get(), H5T_STR_NULLTERM), "cannot pad a string type");
    attribute(name, type.get(), type.get(), value.c_str());
  };
  text("format", model_file_format);
  attribute("version", H5T_STD_I32LE, H5T_NATIVE_INT32, &header.version);
  attribute("n_nodes", H5T_STD_I64LE, H5T_NATIVE_INT64, &header.n_nodes);
  attribute("n_tets", H5T_STD_I64LE, H5T_NATIVE_INT64, &header.n_tets);
  text("source", header.source);
  attribute("source_bytes", H5T_STD_I64LE, H5T_NATIVE_INT64, &header.source_bytes);
  attribute("source_mtime_ns", H5T_STD_I64LE, H5T_NATIVE_INT64, &header.source_mtime_ns);
  const std::uint64_t checksum = model_file::header_checksum(header);
  attribute("header_checksum", H5T_STD_U64LE, H5T_NATIVE_UINT64, &checksum);
}

// Writes the model file `h5` (under .tmp, sealed, renamed): `feed` hands the nodes and tets to
// the writer and returns the tables.
template <class Feed>
PrepareReport write_model(const std::string& h5, const PrepareOptions& options,
                          ModelFileHeader header, Feed&& feed) {
  FDEM_VERIFY(options.block_rows > 0, "model file: block_rows must be positive");
  const Context ctx(h5, "model file", Context::Mode::write);
  const std::string tmp = h5 + ".tmp";
  std::vector<FileRegion> regions;
  {
    const SilenceHdf5Errors silence;
    Handle fcpl = make_plist(ctx, H5P_FILE_CREATE);  // the userblock holds the seal
    ctx.check_status(H5Pset_userblock(fcpl.get(), checkpoint_seal_bytes), "cannot set userblock");
    Handle fapl = make_plist(ctx, H5P_FILE_ACCESS);
    ctx.check_status(H5Pset_libver_bounds(fapl.get(), H5F_LIBVER_V18, H5F_LIBVER_LATEST),
                     "cannot set the file format bounds");
    ctx.check_status(H5Pset_fclose_degree(fapl.get(), H5F_CLOSE_STRONG), "cannot set close degree");
    Handle file = ctx.own(H5Fcreate(tmp.c_str(), H5F_ACC_TRUNC, fcpl.get(), fapl.get()), H5Fclose,
                          "cannot create '" + tmp + "'");
    try {
      Spill spill(ctx, h5 + ".tets.tmp");
      TableWriter writer(ctx, file.get(), spill, options.block_rows);
      const GmshTables tables = feed(writer);
      if (!H5Lexists(file.get(), "/nodes", H5P_DEFAULT)) writer.nodes_announced(0);
      header.version = model_file_version;
      header.n_nodes = tables.n_nodes;
      header.n_tets = tables.n_tets;
      regions = writer.finish(tables);
      write_header(ctx, file.get(), header);
      ctx.check_status(H5Fflush(file.get(), H5F_SCOPE_GLOBAL), "cannot flush '" + tmp + "'");
      ctx.check_status(file.close(), "cannot close '" + tmp + "'");
    } catch (...) {
      file.reset();
      std::remove(tmp.c_str());
      throw;
    }
  }
  try {
    write_checkpoint_seal(tmp, regions, "model file");
  } catch (...) {
    std::remove(tmp.c_str());
    throw;
  }
  if (std::rename(tmp.c_str(), h5.c_str()) != 0) {
    const std::string reason = std::strerror(errno);
    std::remove(tmp.c_str());
    ctx.fail("cannot rename '" + tmp + "' to the final name: " + reason);
  }
  sync_directory_of(h5);
  return {header.n_nodes, header.n_tets};
}

}  // namespace

PrepareReport prepare_model_file(const std::string& msh, const std::string& h5,
                                 const PrepareOptions& options) {
  gmsh::Cursor cur(msh, options.window_bytes);  // InputError for a missing or unreadable file
  ModelFileHeader header;
  header.source = msh;
  struct stat status {};
  if (::stat(msh.c_str(), &status) == 0) {
    header.source_bytes = static_cast<std::int64_t>(status.st_size);
    header.source_mtime_ns =
        static_cast<std::int64_t>(status.st_mtim.tv_sec) * 1000000000 + status.st_mtim.tv_nsec;
  }
  return write_model(h5, options, header, [&](GmshSink& writer) {
    const auto index = make_run_index();
    GmshTables tables = parse_gmsh_sections(cur, msh, *index, writer);
    if (tables.n_tets == 0) {  // as read_gmsh says it: unusable volume elements first
      const std::string label = "Gmsh file '" + msh + "'";
      if (!tables.unsupported.empty())
        throw InputError(label + ", " + tables.unsupported.front().message);
      throw InputError(no_tetrahedra_message(label));
    }
    return tables;
  });
}

void write_model_file(const ModelFileContent& content, const std::string& h5) {
  const std::size_t n = content.node_tag.size(), m = content.tet_tag.size();
  FDEM_VERIFY(content.node_x.size() == 3 * n && content.tet_nodes.size() == 4 * m &&
                  content.tet_entity.size() == m,
              "model file content: array sizes do not match");
  write_model(h5, {}, content.header, [&](GmshSink& writer) {
    writer.nodes_announced(static_cast<std::int64_t>(n));
    for (std::size_t i = 0; i < n; ++i) writer.node_tag(std::int64_t(i), content.node_tag[i]);
    for (std::size_t i = 0; i < n; ++i) {
      const double x[3] = {content.node_x[3 * i], content.node_x[3 * i + 1],
                           content.node_x[3 * i + 2]};
      writer.node_coords(std::int64_t(i), x);
    }
    for (std::size_t t = 0; t < m; ++t) {
      const std::int64_t nodes[4] = {content.tet_nodes[4 * t], content.tet_nodes[4 * t + 1],
                                     content.tet_nodes[4 * t + 2], content.tet_nodes[4 * t + 3]};
      writer.tet(content.tet_tag[t], content.tet_entity[t], nodes);
    }
    GmshTables tables = content.tables;
    tables.n_nodes = static_cast<std::int64_t>(n);
    tables.n_tets = static_cast<std::int64_t>(m);
    return tables;
  });
}

}  // namespace fdem
