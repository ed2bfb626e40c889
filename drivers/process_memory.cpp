#include "drivers/process_memory.hpp"

#include <cstdio>
#include <cstring>
#include <fstream>
#include <string>

#if defined(__GLIBC__)
#include <malloc.h>
#endif

namespace fdem {

namespace {

long status_field_kib(const char* field) {
  std::ifstream status("/proc/self/status");
  std::string line;
  const std::size_t length = std::strlen(field);
  while (std::getline(status, line))
    if (line.compare(0, length, field) == 0) return std::stol(line.substr(length));
  return 0;
}

}  // namespace

long peak_rss_kib() {
  return status_field_kib("VmHWM:");
}

long current_rss_kib() {
  return status_field_kib("VmRSS:");
}

void give_large_blocks_back_when_freed() {
#if defined(__GLIBC__)
  // Fixed thresholds turn off glibc's sliding ones, which after the first large free keep
  // blocks of up to 32 MiB on the heap and up to 64 MiB of freed heap top untrimmed: start-up
  // frees arrays of tens of MiB while others are made, and every such hole would count in the
  // peak RSS. Blocks of 1 MiB or more are mapped on their own and returned on free.
  mallopt(M_MMAP_THRESHOLD, 1 << 20);
  mallopt(M_TRIM_THRESHOLD, 8 << 20);
#endif
}

void release_free_memory() {
#if defined(__GLIBC__)
  malloc_trim(0);
#endif
}

bool reset_peak_rss() {
  std::FILE* f = std::fopen("/proc/self/clear_refs", "w");
  if (!f) return false;
  const bool ok = std::fputs("5", f) >= 0;
  return std::fclose(f) == 0 && ok;
}

}  // namespace fdem
