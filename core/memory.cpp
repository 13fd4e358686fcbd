#include "core/memory.h"

#include <unistd.h>

#include <cstdio>

namespace nebula {

size_t memory_limit_bytes() {
  const long pages = sysconf(_SC_PHYS_PAGES);
  const long page_size = sysconf(_SC_PAGE_SIZE);
  if (pages <= 0 || page_size <= 0) return size_t(1) << 32;
  return static_cast<size_t>(pages) / 2 * static_cast<size_t>(page_size);
}

std::string bytes_text(double bytes) {
  const char* units[] = {"B", "KiB", "MiB", "GiB", "TiB", "PiB", "EiB"};
  int u = 0;
  while (bytes >= 1024.0 && u < 6) {
    bytes /= 1024.0;
    ++u;
  }
  char text[48];
  std::snprintf(text, sizeof text, "%.3g %s", bytes, units[u]);
  return text;
}

std::string over_memory_limit(double bytes, double limit) {
  if (!(bytes > limit)) return "";
  return "needs " + bytes_text(bytes) + ", more than the limit of " + bytes_text(limit) + " (half the physical memory)";
}

}  // namespace nebula
