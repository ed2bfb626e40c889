// The cursor of the Gmsh MSH 4.1 parser (io/gmsh_parser): reads ASCII tokens or raw binary values
// and turns a position into "line N" (ASCII) or "byte offset N" (binary) for messages.  It reads
// either a file held whole in memory or a file streamed through a bounded window (`fdem prepare`:
// memory bounded by the window, not by the file).  Internal to io/.
#pragma once

#include <cstdint>
#include <fstream>
#include <string>
#include <string_view>
#include <vector>

namespace fdem::gmsh {

// Printable excerpt of what was found, for messages.
std::string excerpt(std::string_view text);

// Opens the mesh file `path` for binary reading; a missing file, a directory or an unreadable file
// is an InputError naming it.
std::ifstream open_mesh_file(const std::string& path);

class Cursor {
 public:
  // The whole file in memory (`data` must outlive the cursor); `path` names it in messages.
  Cursor(const std::string& path, std::string_view data);
  // The file `path` read through a window of `window_bytes` (at least 64).  Throws InputError
  // if the file is missing, a directory or unreadable.
  Cursor(const std::string& path, std::size_t window_bytes);

  bool binary = false;  // set once $MeshFormat says "4.1 1 8"
  std::string section;  // e.g. "$Nodes", for messages

  std::uint64_t pos() const { return pos_; }
  std::uint64_t size() const { return size_; }
  bool at_end() const { return pos_ >= size_; }
  std::uint64_t remaining() const { return size_ - pos_; }

  std::string location(std::uint64_t at) const;
  [[noreturn]] void fail_at(std::uint64_t at, const std::string& what) const;
  [[noreturn]] void fail_truncated(std::uint64_t at, const std::string& what) const;

  void skip_space();
  // Rest of the current line (without '\r' and trailing blanks, at most 64 KiB of it); moves
  // past the newline.
  std::string line();
  // Skips to just past the next newline (end of a header line before binary data).
  void skip_rest_of_line();

  std::string_view ascii_token(const std::string& what);  // valid until the next read
  std::int64_t ascii_int(const std::string& what);
  std::string ascii_quoted(const std::string& what);  // a double-quoted name ($PhysicalNames)
  std::uint64_t value_start() const { return token_start_; }  // where the last value started

  template <class T>
  T raw(const std::string& what) {
    if (!have(sizeof(T)))
      fail_truncated(pos_, what + " (" + std::to_string(sizeof(T)) + " bytes, only " +
                               std::to_string(remaining()) + " left)");
    token_start_ = pos_;
    T value;
    copy_out(&value, sizeof(T));
    return value;
  }

  std::int64_t read_size(const std::string& what);  // a count or tag: size_t in binary files
  int read_int(const std::string& what);            // an 'int' field
  double read_double(const std::string& what);      // finite

  // Refuses counts that cannot fit in the rest of the file (damaged or truncated file), before
  // anything is allocated for them.  min_bytes: smallest size of one item (binary layout).
  void check_count(std::int64_t count, std::size_t min_bytes, const std::string& what) const;
  void skip_bytes(std::uint64_t bytes, const std::string& what);
  void expect_end(const std::string& name);
  // Skips a section this reader does not use, up to and including its end marker.
  void skip_section(const std::string& name, std::uint64_t start);

 private:
  // Makes [pos_, pos_ + n) readable if the file has it; false at the end of the file.
  bool have(std::size_t n) { return pos_ + n <= end_ || refill(pos_, n); }
  // Reads on, keeping [keep, end_) in the window, until [pos_, pos_ + n) is in it or the file
  // ends; grows the window when `keep` already fills it.
  bool refill(std::uint64_t keep, std::size_t n);
  char at(std::uint64_t p) const { return base_[p - begin_]; }
  void copy_out(void* to, std::size_t n);
  std::uint64_t line_of(std::uint64_t at) const;

  std::string path_;
  const char* base_ = nullptr;  // byte begin_ of the file
  std::uint64_t begin_ = 0, end_ = 0, size_ = 0, pos_ = 0, token_start_ = 0;
  // Streaming only:
  std::vector<char> window_;
  mutable std::ifstream in_;
  bool streaming_ = false, seeked_ = false;
  std::uint64_t newlines_before_ = 0;  // '\n' bytes in [0, begin_) (ASCII, before any seek)
};

}  // namespace fdem::gmsh
