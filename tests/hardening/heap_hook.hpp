// The hardening tests' replacement of the global operator new / delete (in
// heap_hook.cpp; one per executable): it counts the bytes and blocks the
// process holds through operator new, and can make one chosen allocation fail,
// to test that every allocation failure becomes an error status.
#pragma once

namespace sogmm::test::heap {

/// Bytes currently allocated through operator new (all threads).
long long live_bytes();
/// Blocks currently allocated through operator new (all threads).
long long live_blocks();
/// Highest live_bytes() since the last reset_peak().
long long peak_bytes();
/// Sets the peak to the current live_bytes().
void reset_peak();

/// Makes the n-th operator new from now on (n >= 1, counted over all
/// threads) fail as if memory were exhausted: std::bad_alloc, or nullptr for
/// the nothrow forms. Only that one fails.
void fail_nth_allocation(long long n);
/// Stops failure injection; true if the chosen allocation was reached.
bool stop_failing();

}  // namespace sogmm::test::heap
