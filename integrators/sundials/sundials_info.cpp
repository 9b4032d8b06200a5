#include "integrators/sundials/sundials_info.hpp"

#include <sundials/sundials_version.h>

namespace shelldyn {

std::string sundials_version() {
  char buf[64] = {0};
  if (SUNDIALSGetVersion(buf, sizeof(buf)) != 0) return "unknown";
  return buf;
}

}  // namespace shelldyn
