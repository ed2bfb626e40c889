// HDF5 plumbing shared by the collective parallel-HDF5 writers of parallel/ (checkpoint.cpp,
// xdmf_output.cpp): owned identifiers, silenced automatic error printing, error text naming the
// file (a file being written fails as IoError, one being read as InputError), MPI-IO file access
// and collective transfer property lists, a writer of datasets whose rows each rank fills as
// hyperslabs with collective I/O, and the space claim made before a collective write.  Internal
// to parallel/.
#pragma once

#include <hdf5.h>

#include <algorithm>
#include <array>
#include <cstdint>
#include <optional>
#include <string>
#include <type_traits>
#include <vector>

#include "core/error.hpp"
#include "parallel/communicator.hpp"

namespace fdem::hdf5 {

// ---------------------------------------------------------------------------------------------
// HDF5 plumbing: owned identifiers, silenced automatic error printing, error text.

// Owns one HDF5 identifier and closes it with the matching H5?close.
class Handle {
 public:
  using Closer = herr_t (*)(hid_t);
  Handle() = default;
  Handle(hid_t id, Closer closer) : id_(id), closer_(closer) {}
  Handle(Handle&& other) noexcept : id_(other.id_), closer_(other.closer_) { other.id_ = -1; }
  Handle& operator=(Handle&& other) noexcept {
    if (this != &other) {
      reset();
      id_ = other.id_;
      closer_ = other.closer_;
      other.id_ = -1;
    }
    return *this;
  }
  Handle(const Handle&) = delete;
  Handle& operator=(const Handle&) = delete;
  ~Handle() { reset(); }

  hid_t get() const { return id_; }
  bool valid() const { return id_ >= 0; }
  // Closes now and returns the status (for the file, whose close flushes and can fail).
  herr_t close() {
    herr_t status = 0;
    if (id_ >= 0 && closer_) status = closer_(id_);
    id_ = -1;
    return status;
  }
  void reset() { close(); }

 private:
  hid_t id_ = -1;
  Closer closer_ = nullptr;
};

// HDF5 prints its error stack to stderr by default; fdem reports errors as messages instead.
// Restores the previous setting at scope exit (other code may rely on it).
class SilenceHdf5Errors {
 public:
  SilenceHdf5Errors() {
    saved_ = H5Eget_auto2(H5E_DEFAULT, &function_, &data_) >= 0;
    H5Eset_auto2(H5E_DEFAULT, nullptr, nullptr);
  }
  ~SilenceHdf5Errors() {
    if (saved_) H5Eset_auto2(H5E_DEFAULT, function_, data_);
  }
  SilenceHdf5Errors(const SilenceHdf5Errors&) = delete;
  SilenceHdf5Errors& operator=(const SilenceHdf5Errors&) = delete;

 private:
  bool saved_ = false;
  H5E_auto2_t function_ = nullptr;
  void* data_ = nullptr;
};

// The two most specific causes on the current HDF5 error stack as one line; clears the stack.
std::string hdf5_error_text();

// Exit code of an I/O failure (README: exit codes), for the abort of a failed collective write.
constexpr int io_failure_exit_code = 4;

// Messages name the file the user gave (the final path, also while writing the .tmp).  A file
// that cannot be read is bad input (the user named it); one that cannot be written is an I/O
// failure (disk full, quota, permissions).
class Context {
 public:
  enum class Mode { read, write };
  // kind: what the file is, first word of every message ("checkpoint", "frame").
  Context(std::string path, std::string kind, Mode mode)
      : path_(std::move(path)), kind_(std::move(kind)), mode_(mode) {}
  [[noreturn]] void fail(const std::string& what) const {
    const std::string message = kind_ + " '" + path_ + "': " + what;
    if (mode_ == Mode::write) throw IoError(message);
    throw InputError(message);
  }
  [[noreturn]] void fail_hdf5(const std::string& what) const {
    fail(what + " (HDF5: " + hdf5_error_text() + ")");
  }
  // Data that does not match its checksum: the file was changed after it was written.
  [[noreturn]] void corrupt(const std::string& what) const {
    throw InputError(kind_ + " corrupt: " + what + " (file '" + path_ +
                     "' does not hold what was written; use an earlier " + kind_ + ")");
  }
  hid_t check(hid_t id, const std::string& what) const {
    if (id < 0) fail_hdf5(what);
    return id;
  }
  void check_status(herr_t status, const std::string& what) const {
    if (status < 0) fail_hdf5(what);
  }
  // For the collective data writes, flush and close: the file system may fail them on some ranks
  // only (the aggregators that write), which then leave the collective sequence at another point
  // than the others.  A collective error report could pair with HDF5's own collectives and hang,
  // so on N ranks (after abort_on) every rank ends here (exit code 4, I/O failure).  The writers
  // claim the file's space first (reserve_space), so a full disk is normally reported
  // collectively before this.
  void check_collective_write(herr_t status, const std::string& what) const {
    if (status >= 0) return;
    if (abort_comm_ && abort_comm_->size() > 1)
      abort_comm_->abort_all("I/O failure: " + kind_ + " '" + path_ + "': " + what +
                                 " (HDF5: " + hdf5_error_text() + ")",
                             io_failure_exit_code);
    fail_hdf5(what);
  }
  void abort_on(const Communicator& comm) { abort_comm_ = &comm; }
  Handle own(hid_t id, Handle::Closer closer, const std::string& what) const {
    return Handle(check(id, what), closer);
  }
  const std::string& path() const { return path_; }
  const std::string& kind() const { return kind_; }

 private:
  std::string path_, kind_;
  Mode mode_;
  const Communicator* abort_comm_ = nullptr;
};

inline Handle make_plist(const Context& ctx, hid_t cls) {
  return ctx.own(H5Pcreate(cls), H5Pclose, "cannot create a property list");
}

inline Handle make_space(const Context& ctx, const std::vector<hsize_t>& dims) {
  if (dims.empty()) return ctx.own(H5Screate(H5S_SCALAR), H5Sclose, "cannot create a dataspace");
  return ctx.own(H5Screate_simple(static_cast<int>(dims.size()), dims.data(), nullptr), H5Sclose,
                 "cannot create a dataspace");
}

// File access over `comm` with MPI-IO; metadata reads and writes done collectively (every rank
// performs the same metadata operations in the same order here), and closing the file closing
// whatever is still open in it (H5F_CLOSE_STRONG).  `hints`: MPI-IO hints (MPI_Info, e.g.
// striping_factor) for the files opened with it; MPI_INFO_NULL for none.
Handle make_mpio_access(const Context& ctx, const Communicator& comm,
                        MPI_Info hints = MPI_INFO_NULL);

inline Handle make_collective_transfer(const Context& ctx) {
  Handle dxpl = make_plist(ctx, H5P_DATASET_XFER);
  ctx.check_status(H5Pset_dxpl_mpio(dxpl.get(), H5FD_MPIO_COLLECTIVE),
                   "cannot set collective transfer");
  return dxpl;
}

// A run of consecutive file rows [start, start + count).
struct Run {
  hsize_t start = 0, count = 0;
};

// HDF5 types of the values: native in memory, fixed little-endian in the file.
template <class T>
hid_t native_type() {
  if constexpr (std::is_same_v<T, double>)
    return H5T_NATIVE_DOUBLE;
  else if constexpr (std::is_same_v<T, std::int64_t>)
    return H5T_NATIVE_INT64;
  else if constexpr (std::is_same_v<T, std::uint64_t>)
    return H5T_NATIVE_UINT64;
  else if constexpr (std::is_same_v<T, std::int32_t>)
    return H5T_NATIVE_INT32;
  else {
    static_assert(std::is_same_v<T, std::uint8_t>, "HDF5 values here are f64, i64, u64, i32, u8");
    return H5T_NATIVE_UINT8;
  }
}
template <class T>
hid_t file_type() {
  if constexpr (std::is_same_v<T, double>)
    return H5T_IEEE_F64LE;
  else if constexpr (std::is_same_v<T, std::int64_t>)
    return H5T_STD_I64LE;
  else if constexpr (std::is_same_v<T, std::int32_t>)
    return H5T_STD_I32LE;
  else {
    static_assert(std::is_same_v<T, std::uint8_t>, "datasets here are f64, i64, i32, u8");
    return H5T_STD_U8LE;
  }
}

class Writer {
 public:
  Writer(const Context& ctx, hid_t file) : ctx_(ctx), file_(file) {
    dxpl_ = make_collective_transfer(ctx);
    dcpl_ = make_plist(ctx, H5P_DATASET_CREATE);
    // Every row is written, so skip HDF5's fill pass over the file.
    ctx.check_status(H5Pset_fill_time(dcpl_.get(), H5D_FILL_TIME_NEVER), "cannot set fill time");
  }

  Handle group(const char* name, bool track_attribute_order = false) const {
    Handle gcpl = make_plist(ctx_, H5P_GROUP_CREATE);
    if (track_attribute_order)
      ctx_.check_status(
          H5Pset_attr_creation_order(gcpl.get(), H5P_CRT_ORDER_TRACKED | H5P_CRT_ORDER_INDEXED),
          "cannot track attribute order");
    return ctx_.own(H5Gcreate2(file_, name, H5P_DEFAULT, gcpl.get(), H5P_DEFAULT), H5Gclose,
                    std::string("cannot create group ") + name);
  }

  // Scalar attribute (metadata: every rank passes the same value).
  void attribute(hid_t object, const std::string& name, hid_t file_type, hid_t mem_type,
                 const void* value) const {
    Handle space = make_space(ctx_, {});
    Handle attr =
        ctx_.own(H5Acreate2(object, name.c_str(), file_type, space.get(), H5P_DEFAULT, H5P_DEFAULT),
                 H5Aclose, "cannot create attribute " + name);
    ctx_.check_status(H5Awrite(attr.get(), mem_type, value), "cannot write attribute " + name);
  }
  void string_attribute(hid_t object, const std::string& name, const std::string& text) const {
    Handle type = ctx_.own(H5Tcopy(H5T_C_S1), H5Tclose, "cannot create a string type");
    ctx_.check_status(H5Tset_size(type.get(), text.size() + 1), "cannot size a string type");
    ctx_.check_status(H5Tset_strpad(type.get(), H5T_STR_NULLTERM), "cannot pad a string type");
    attribute(object, name, type.get(), type.get(), text.c_str());
  }

  // Dataset of `n_rows` × `width` (width 0: one-dimensional) where this rank writes `data` (its
  // rows in order, `width` or 1 values each) to the file rows `runs`; with `checksum`, a uint64
  // attribute "checksum" of that value (the same on every rank).  Collective.  A failed data
  // write ends every rank (Context::check_collective_write).
  template <class T>
  void rows(hid_t group, const char* name, hsize_t n_rows, hsize_t width,
            const std::vector<T>& data, const std::vector<Run>& runs,
            std::optional<std::uint64_t> checksum = std::nullopt) const {
    const hsize_t columns = width == 0 ? 1 : width;
    std::vector<hsize_t> dims{n_rows};
    if (width != 0) dims.push_back(width);
    Handle file_space = make_space(ctx_, dims);
    const std::string what = std::string("dataset ") + name;
    Handle dataset = ctx_.own(H5Dcreate2(group, name, file_type<T>(), file_space.get(), H5P_DEFAULT,
                                         dcpl_.get(), H5P_DEFAULT),
                              H5Dclose, "cannot create " + what);
    if (checksum)
      attribute(dataset.get(), "checksum", H5T_STD_U64LE, H5T_NATIVE_UINT64, &*checksum);
    if (n_rows * columns == 0) return;  // the same on every rank: nothing to write

    ctx_.check_status(H5Sselect_none(file_space.get()), "cannot select in " + what);
    hsize_t local_values = 0;
    for (const Run& run : runs) {
      const std::array<hsize_t, 2> start{run.start, 0}, count{run.count, columns};
      ctx_.check_status(H5Sselect_hyperslab(file_space.get(), H5S_SELECT_OR, start.data(), nullptr,
                                            count.data(), nullptr),
                        "cannot select rows in " + what);
      local_values += run.count * columns;
    }
    FDEM_VERIFY(local_values == data.size(), "HDF5 rows do not match their selection");
    // A rank without rows still takes part in the collective write, with empty selections.
    Handle mem_space = make_space(ctx_, {std::max<hsize_t>(local_values, 1)});
    if (local_values == 0)
      ctx_.check_status(H5Sselect_none(mem_space.get()), "cannot select in " + what);
    static const T dummy{};
    const void* buffer = data.empty() ? static_cast<const void*>(&dummy) : data.data();
    ctx_.check_collective_write(H5Dwrite(dataset.get(), native_type<T>(), mem_space.get(),
                                         file_space.get(), dxpl_.get(), buffer),
                                "cannot write " + what);
  }

 private:
  const Context& ctx_;
  hid_t file_;
  Handle dxpl_, dcpl_;
};

// Rank 0 (or a rank alone): claims `bytes` for `path` and frees them again, so that a full disk
// (or a file size limit) is found before the collective write, where every rank can report it
// together: ctx.fail "no room for the <kind> (about N MB): <reason>".  File systems without
// fallocate are not probed.
void reserve_space(const Context& ctx, const std::string& path, double bytes);

// Best effort: make the rename of a file in `path`'s directory durable (fsync of the directory).
void sync_directory_of(const std::string& path);

}  // namespace fdem::hdf5
