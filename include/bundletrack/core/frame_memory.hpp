#pragma once

#if defined(__GLIBC__)
#include <malloc.h>
#endif

namespace bundletrack {

/// Asks the C library to keep the memory of freed frames for the next one. Every frame allocates
/// and frees image-sized buffers (a 640x480 frame's depth, points and normals are 8.6 MiB; a
/// surface grid at step 1 is 7.4 MiB); glibc serves blocks above its mmap threshold with fresh
/// pages and returns freed heap tops above its trim threshold to the system, so each frame paid
/// page faults and zeroing for memory it had just given back (5-20 % of bundletrack_track's
/// whole run on the shared sequences). Blocks up to 32 MiB (glibc's largest dynamic threshold) then come
/// from the heap, and up to 64 MiB of free heap top is kept: a process holds at most that much
/// more than it uses. A program calls it once, before its first frame; elsewhere than glibc it does
/// nothing. Returns whether both settings were taken.
inline bool keepFreedFrameMemory() {
#if defined(__GLIBC__)
  constexpr int kLargestHeapBlock = 32 << 20, kKeptFreeTop = 64 << 20;
  return mallopt(M_MMAP_THRESHOLD, kLargestHeapBlock) == 1 && mallopt(M_TRIM_THRESHOLD, kKeptFreeTop) == 1;
#else
  return false;
#endif
}

}  // namespace bundletrack
