#include "parallel/checkpoint_seal.hpp"

#include <algorithm>
#include <cerrno>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <sstream>

#include "core/error.hpp"
#include "parallel/checkpoint_checksum.hpp"

namespace fdem {

namespace {

constexpr const char* seal_magic = "fdem-checkpoint-seal 1\n";

// FNV-1a over the bytes of [start, end) of `in` outside the sorted, disjoint `data` regions.
bool metadata_checksum(std::ifstream& in, std::uint64_t start, std::uint64_t end,
                       const std::vector<FileRegion>& data, std::uint64_t& hash) {
  using namespace checksum_detail;
  hash = fnv_offset;
  std::vector<char> buffer(1 << 16);
  std::uint64_t at = start;
  std::size_t next = 0;
  while (at < end) {
    while (next < data.size() && data[next].offset + data[next].size <= at) ++next;
    if (next < data.size() && data[next].offset <= at) {  // inside raw data: skip it
      at = data[next].offset + data[next].size;
      continue;
    }
    const std::uint64_t stop = std::min<std::uint64_t>(
        {end, next < data.size() ? data[next].offset : end, at + buffer.size()});
    in.seekg(static_cast<std::streamoff>(at));
    in.read(buffer.data(), static_cast<std::streamsize>(stop - at));
    if (!in) return false;
    for (std::uint64_t k = 0; k < stop - at; ++k)
      hash = (hash ^ static_cast<unsigned char>(buffer[k])) * fnv_prime;
    at = stop;
  }
  hash = mix(hash);
  return true;
}

std::uint64_t file_size(std::ifstream& in) {
  in.seekg(0, std::ios::end);
  return static_cast<std::uint64_t>(in.tellg());
}

std::string hex(std::uint64_t value) {
  char text[17];
  std::snprintf(text, sizeof text, "%016llx", static_cast<unsigned long long>(value));
  return text;
}

}  // namespace

void write_checkpoint_seal(const std::string& path, std::vector<FileRegion> data,
                           const std::string& kind) {
  data.erase(std::remove_if(data.begin(), data.end(), [](const FileRegion& r) { return !r.size; }),
             data.end());
  std::sort(data.begin(), data.end(),
            [](const FileRegion& a, const FileRegion& b) { return a.offset < b.offset; });
  std::ifstream in(path, std::ios::binary);
  std::uint64_t hash = 0;
  if (!in || !metadata_checksum(in, checkpoint_seal_bytes, file_size(in), data, hash))
    throw IoError(kind + " '" + path + "': cannot read it back to seal it");
  in.close();
  std::ostringstream text;
  text << seal_magic << "metadata " << hex(hash) << "\nregions " << data.size() << "\n";
  for (const FileRegion& r : data) text << r.offset << ' ' << r.size << '\n';
  std::string seal = text.str();
  seal += "seal " + hex(text_checksum(seal)) + "\n";
  FDEM_VERIFY(seal.size() < checkpoint_seal_bytes, "checkpoint seal larger than its userblock");
  std::fstream out(path, std::ios::in | std::ios::out | std::ios::binary);
  out.write(seal.data(), static_cast<std::streamsize>(seal.size()));
  out.flush();
  if (!out)
    throw IoError(kind + " '" + path +
                  "': cannot write its checksum block: " + std::strerror(errno));
}

SealState check_checkpoint_seal(const std::string& path, std::string& problem) {
  std::ifstream in(path, std::ios::binary);
  std::string block(checkpoint_seal_bytes, '\0');
  if (!in.read(&block[0], static_cast<std::streamsize>(block.size()))) return SealState::absent;
  if (block.compare(0, std::strlen(seal_magic), seal_magic) != 0) return SealState::absent;
  // The seal's own text, checked by its last line.
  const std::size_t line = block.find("\nseal ");
  const std::size_t last = line == std::string::npos ? line : line + 1;
  const std::size_t end = block.find('\n', last == std::string::npos ? 0 : last);
  if (last == std::string::npos || end == std::string::npos ||
      block.substr(last + 5, end - last - 5) != hex(text_checksum(block.substr(0, last)))) {
    problem = "its checksum block (the HDF5 userblock) is damaged";
    return SealState::damaged;
  }
  std::istringstream text(block.substr(std::strlen(seal_magic), last - std::strlen(seal_magic)));
  std::string word, stored;
  std::size_t count = 0;
  text >> word >> stored >> word >> count;
  std::vector<FileRegion> data(count);
  for (FileRegion& r : data) text >> r.offset >> r.size;
  std::uint64_t hash = 0;
  const std::uint64_t size = file_size(in);
  for (const FileRegion& r : data)
    if (r.offset + r.size > size) {
      problem = "it is shorter than its datasets (" + std::to_string(size) + " bytes)";
      return SealState::damaged;
    }
  if (!text || !metadata_checksum(in, checkpoint_seal_bytes, size, data, hash) ||
      hex(hash) != stored) {
    problem = "its HDF5 metadata (file structure) does not match its checksum";
    return SealState::damaged;
  }
  return SealState::intact;
}

}  // namespace fdem
