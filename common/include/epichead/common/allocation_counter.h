#pragma once
// Heap allocations made by this process so far, for proving that a hot path allocates nothing
// after start-up (STYLE.md): take the count before and after the path and compare. Counted by
// replacing the global operator new (the standard's own hook), so only a program that links the
// epichead_allocation_counter object library has it: the bench tool and the allocation tests.
namespace epichead::common {

// Every form of global operator new, all threads (a relaxed atomic increment, about 1 ns).
unsigned long long allocation_count();

}  // namespace epichead::common
