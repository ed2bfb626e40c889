#include "io/gmsh_cursor.hpp"

#include <algorithm>
#include <cctype>
#include <charconv>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <limits>
#include <system_error>

#include "core/error.hpp"

namespace fdem::gmsh {

namespace {

constexpr std::size_t kMaxLine = 1 << 16;   // bytes of a line kept by line()
constexpr std::size_t kMaxToken = 1 << 20;  // longer tokens are a damaged file

bool space(char c) {
  return std::isspace(static_cast<unsigned char>(c)) != 0;
}

}  // namespace

std::string excerpt(std::string_view text) {
  constexpr std::size_t kMax = 40;
  std::string out;
  for (std::size_t i = 0; i < text.size() && i < kMax; ++i) {
    const unsigned char ch = static_cast<unsigned char>(text[i]);
    out += std::isprint(ch) ? static_cast<char>(ch) : '?';
  }
  if (text.size() > kMax) out += "...";
  return out;
}

std::ifstream open_mesh_file(const std::string& path) {
  namespace fs = std::filesystem;
  std::error_code ec;
  if (!fs::exists(path, ec)) {
    throw InputError("Gmsh mesh file '" + path +
                     "' does not exist (relative paths are taken from " +
                     fs::current_path(ec).string() + "); expected an MSH 4.1 file from Gmsh.");
  }
  if (fs::is_directory(path, ec)) {
    throw InputError("Gmsh mesh file '" + path + "' is a directory; expected an MSH 4.1 file.");
  }
  std::ifstream in(path, std::ios::binary);
  if (!in) {
    throw InputError("Gmsh mesh file '" + path +
                     "' exists but cannot be opened for reading (check its permissions).");
  }
  return in;
}

Cursor::Cursor(const std::string& path, std::string_view data)
    : path_(path), base_(data.data()), end_(data.size()), size_(data.size()) {}

Cursor::Cursor(const std::string& path, std::size_t window_bytes)
    : path_(path), window_(std::max<std::size_t>(window_bytes, 64)), streaming_(true) {
  in_ = open_mesh_file(path);
  in_.seekg(0, std::ios::end);
  const std::streamoff size = in_.tellg();
  in_.seekg(0, std::ios::beg);
  if (size < 0) throw InputError("Gmsh mesh file '" + path + "' could not be read (I/O error).");
  size_ = static_cast<std::uint64_t>(size);
  base_ = window_.data();
}

bool Cursor::refill(std::uint64_t keep, std::size_t n) {
  if (!streaming_ || end_ >= size_) return false;
  keep = std::clamp(keep, begin_, end_);
  if (!seeked_)
    newlines_before_ += static_cast<std::uint64_t>(
        std::count(window_.data(), window_.data() + (keep - begin_), '\n'));
  std::memmove(window_.data(), window_.data() + (keep - begin_), end_ - keep);
  begin_ = keep;
  while (pos_ + n > end_ && end_ < size_) {
    if (end_ - begin_ == window_.size() || pos_ + n - begin_ > window_.size())
      window_.resize(std::max<std::size_t>(2 * window_.size(), pos_ + n - begin_));
    const std::size_t want = static_cast<std::size_t>(
        std::min<std::uint64_t>(window_.size() - (end_ - begin_), size_ - end_));
    in_.read(window_.data() + (end_ - begin_), static_cast<std::streamsize>(want));
    const auto got = static_cast<std::uint64_t>(in_.gcount());
    if (got == 0) throw InputError("Gmsh mesh file '" + path_ + "' could not be read (I/O error).");
    end_ += got;
  }
  base_ = window_.data();
  return pos_ + n <= end_;
}

void Cursor::copy_out(void* to, std::size_t n) {
  std::memcpy(to, base_ + (pos_ - begin_), n);
  pos_ += n;
}

std::uint64_t Cursor::line_of(std::uint64_t at) const {
  at = std::min(at, size_);
  std::uint64_t newlines = 0;
  char last = '\0';  // the byte before `at`
  if (!streaming_) {
    newlines = static_cast<std::uint64_t>(std::count(base_, base_ + at, '\n'));
    if (at > 0) last = base_[at - 1];
  } else if (!seeked_ && at > begin_ && at <= end_) {
    newlines = newlines_before_ + static_cast<std::uint64_t>(std::count(
                                      window_.data(), window_.data() + (at - begin_), '\n'));
    last = at == size_ ? window_[at - 1 - begin_] : '\0';
  } else {  // a message about a place outside the window: count from the start of the file
    std::ifstream again(path_, std::ios::binary);
    std::vector<char> buffer(1 << 16);
    std::uint64_t done = 0;
    while (done < at && again) {
      again.read(buffer.data(),
                 static_cast<std::streamsize>(std::min<std::uint64_t>(buffer.size(), at - done)));
      const auto got = static_cast<std::size_t>(again.gcount());
      if (got == 0) break;
      newlines += static_cast<std::uint64_t>(std::count(buffer.data(), buffer.data() + got, '\n'));
      last = buffer[got - 1];
      done += got;
    }
  }
  // End of file just after a final newline still belongs to the last line.
  if (at == size_ && at > 0 && last == '\n') --newlines;
  return 1 + newlines;
}

std::string Cursor::location(std::uint64_t at) const {
  if (binary) return "byte offset " + std::to_string(at);
  return "line " + std::to_string(line_of(at));
}

void Cursor::fail_at(std::uint64_t at, const std::string& what) const {
  throw InputError("Gmsh file '" + path_ + "', " + location(at) +
                   (section.empty() ? "" : " (in " + section + ")") + ": " + what);
}

void Cursor::fail_truncated(std::uint64_t at, const std::string& what) const {
  fail_at(at, "unexpected end of file while reading " + what +
                  "; the file is truncated (incomplete copy or interrupted export?), re-export "
                  "it from Gmsh.");
}

void Cursor::skip_space() {
  while (have(1) && space(at(pos_))) ++pos_;
}

std::string Cursor::line() {
  std::string out;
  while (have(1)) {
    const char c = at(pos_++);
    if (c == '\n') break;
    if (out.size() < kMaxLine) out += c;
  }
  while (!out.empty() && space(out.back())) out.pop_back();
  return out;
}

void Cursor::skip_rest_of_line() {
  while (have(1))
    if (at(pos_++) == '\n') return;
}

std::string_view Cursor::ascii_token(const std::string& what) {
  skip_space();
  if (!have(1)) fail_truncated(size_, what);
  token_start_ = pos_;
  while ((pos_ < end_ || refill(token_start_, 1)) && !space(at(pos_))) {
    ++pos_;
    if (pos_ - token_start_ > kMaxToken)
      fail_at(token_start_, "expected " + what + ", found '" +
                                excerpt(std::string_view(base_ + (token_start_ - begin_), 64)) +
                                "' (a token of more than 1 MiB); the file is damaged.");
  }
  return std::string_view(base_ + (token_start_ - begin_), pos_ - token_start_);
}

std::int64_t Cursor::ascii_int(const std::string& what) {
  const std::string_view token = ascii_token(what);
  std::int64_t value = 0;
  const auto [end, ec] = std::from_chars(token.data(), token.data() + token.size(), value);
  if (ec != std::errc() || end != token.data() + token.size()) {
    fail_at(token_start_, "expected " + what + " (an integer), found '" + excerpt(token) + "'.");
  }
  return value;
}

std::string Cursor::ascii_quoted(const std::string& what) {
  skip_space();
  if (!have(1)) fail_truncated(size_, what);
  const std::uint64_t start = pos_;
  std::string text;  // the line from `start` (its first 41 bytes suffice for a message)
  bool closed = false;
  std::uint64_t p = start;
  while (p < end_ || refill(start, p - pos_ + 1)) {
    const char c = at(p++);
    if (c == '\n') break;
    if (p - 1 > start && c == '"' && at(start) == '"') {
      closed = true;
      break;
    }
    if (text.size() < kMaxLine) text += c;
  }
  if (!closed)
    fail_at(start, "expected " + what + " in double quotes, found '" + excerpt(text) + "'.");
  pos_ = p;
  return text.substr(1);
}

std::int64_t Cursor::read_size(const std::string& what) {
  if (binary) {
    const std::uint64_t value = raw<std::uint64_t>(what);
    if (value > static_cast<std::uint64_t>(std::numeric_limits<std::int64_t>::max())) {
      fail_at(token_start_, "expected " + what + ", found the impossible value " +
                                std::to_string(value) + "; the file is damaged.");
    }
    return static_cast<std::int64_t>(value);
  }
  const std::int64_t value = ascii_int(what);
  if (value < 0) {
    fail_at(token_start_,
            "expected " + what + " (a non-negative integer), found " + std::to_string(value) + ".");
  }
  return value;
}

int Cursor::read_int(const std::string& what) {
  if (binary) return raw<std::int32_t>(what);
  const std::int64_t value = ascii_int(what);
  if (value < std::numeric_limits<int>::min() || value > std::numeric_limits<int>::max()) {
    fail_at(token_start_,
            "expected " + what + " (a 32-bit integer), found " + std::to_string(value) + ".");
  }
  return static_cast<int>(value);
}

double Cursor::read_double(const std::string& what) {
  double value = 0.0;
  if (binary) {
    value = raw<double>(what);
  } else {
    const std::string_view token = ascii_token(what);
    const auto [end, ec] = std::from_chars(token.data(), token.data() + token.size(), value);
    if (ec != std::errc() || end != token.data() + token.size()) {
      fail_at(token_start_, "expected " + what + " (a number), found '" + excerpt(token) + "'.");
    }
  }
  if (!std::isfinite(value)) fail_at(token_start_, "expected " + what + ", found NaN or infinity.");
  return value;
}

void Cursor::check_count(std::int64_t count, std::size_t min_bytes, const std::string& what) const {
  const std::size_t bytes_each = binary ? min_bytes : 2;  // ASCII: a digit and a separator
  if (count > 0 && static_cast<std::uint64_t>(count) > remaining() / bytes_each) {
    fail_at(size_, "unexpected end of file: " + std::to_string(count) + " " + what +
                       " are announced, which need at least " +
                       std::to_string(static_cast<std::uint64_t>(count) * bytes_each) +
                       " bytes, but only " + std::to_string(remaining()) +
                       " remain; the file is truncated (incomplete copy or interrupted "
                       "export?), re-export it from Gmsh.");
  }
}

void Cursor::skip_bytes(std::uint64_t bytes, const std::string& what) {
  if (remaining() < bytes) fail_truncated(pos_, what);
  pos_ += bytes;
  if (streaming_ && pos_ > end_) {  // jump: the window starts afresh at pos_
    begin_ = end_ = pos_;
    seeked_ = true;
    in_.clear();
    in_.seekg(static_cast<std::streamoff>(pos_));
  }
}

void Cursor::expect_end(const std::string& name) {
  skip_space();
  if (at_end()) fail_truncated(size_, "'$End" + name + "'");
  const std::uint64_t start = pos_;
  const std::string found = line();
  if (found != "$End" + name) {
    fail_at(start, "expected '$End" + name +
                       "' (the counts in the section header do not match "
                       "its content), found '" +
                       excerpt(found) + "'.");
  }
}

void Cursor::skip_section(const std::string& name, std::uint64_t start) {
  const std::string marker = "\n$End" + name;
  // From the newline that ended the section's header line.
  pos_ = std::max(pos_ > 0 ? pos_ - 1 : 0, begin_);
  while (have(marker.size())) {
    if (at(pos_) == '\n' &&
        std::memcmp(base_ + (pos_ - begin_), marker.data(), marker.size()) == 0) {
      ++pos_;
      line();
      return;
    }
    ++pos_;
  }
  fail_at(start, "section '$" + name + "' has no '$End" + name +
                     "' marker; the file is truncated or damaged.");
}

}  // namespace fdem::gmsh
