// The hardening binary counts every operator new / delete of the process
// (test_limits.cpp replaces them). These accessors let other tests measure
// the peak heap of a call. Allocations made with malloc (zstd's contexts, a
// few hundred KiB) are not counted.
#pragma once

namespace sogmm::test {

/// Bytes currently allocated with operator new.
long long heap_live_bytes();
/// Starts a measurement: the peak becomes the current live size.
void heap_reset_peak();
/// Largest live size since the last heap_reset_peak().
long long heap_peak_bytes();

}  // namespace sogmm::test
