#pragma once
// How much memory a run may take, and sizes as messages print them. Every
// loader and command estimates what it will allocate and compares it with
// memory_limit_bytes() before allocating (issue 17: a refusal naming the
// figure and the limit, never std::bad_alloc).
#include <cstddef>
#include <string>

namespace nebula {

// Half the physical memory (sysconf), or 4 GiB when it cannot be known.
size_t memory_limit_bytes();

// "3.55 PiB", "512 MiB", "12 B": three significant digits and a binary unit.
std::string bytes_text(double bytes);

// "needs X, more than the limit of Y (half the physical memory)" when `bytes`
// exceeds `limit`, else "".
std::string over_memory_limit(double bytes, double limit = double(memory_limit_bytes()));

}  // namespace nebula
