// Memory of this process as the kernel counts it (Linux /proc; 0 elsewhere): peak resident set
// size, handing freed heap back, and restarting the peak count so that start-up and the step loop
// can be measured separately.
#pragma once

namespace fdem {

// Peak resident set size of this process so far (VmHWM, KiB); 0 where unknown.
long peak_rss_kib();
// Current resident set size (VmRSS, KiB); 0 where unknown.
long current_rss_kib();
// Call first in main: blocks of 1 MiB or more go back to the kernel as soon as they are freed
// (glibc mallopt; nothing elsewhere).
void give_large_blocks_back_when_freed();
// Returns freed heap pages to the kernel (glibc malloc_trim): start-up buffers that were freed
// stop counting against the node's memory.
void release_free_memory();
// Restarts the peak count at the current RSS (writes 5 to /proc/self/clear_refs); false where the
// kernel does not allow it (then peak_rss_kib() keeps counting from the start).
bool reset_peak_rss();

}  // namespace fdem
