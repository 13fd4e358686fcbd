#include "hdf5io/hdf5_support.h"

#include <algorithm>

namespace nebula::hdf5io {

std::string hdf5_reason() {
  std::string reason;
  auto take_first = [](unsigned n, const H5E_error2_t* e, void* out) -> herr_t {
    if (n == 0 && e->desc != nullptr) *static_cast<std::string*>(out) = e->desc;
    return 0;
  };
  H5Ewalk2(H5E_DEFAULT, H5E_WALK_UPWARD, take_first, &reason);
  const std::string marker = "error message = '";
  const size_t at = reason.find(marker);
  if (at != std::string::npos) {
    const size_t begin = at + marker.size();
    reason = reason.substr(begin, reason.find('\'', begin) - begin);
  }
  std::replace(reason.begin(), reason.end(), '\n', ' ');
  return reason;
}

std::string with_reason(const std::string& what) {
  const std::string reason = hdf5_reason();
  return reason.empty() ? what : what + " (" + reason + ")";
}

std::mutex& hdf5_mutex() {
  static std::mutex m;
  return m;
}

void silence_hdf5_errors() { H5Eset_auto2(H5E_DEFAULT, nullptr, nullptr); }

}  // namespace nebula::hdf5io
