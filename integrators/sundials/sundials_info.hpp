// Version of the SUNDIALS library linked at run time (recorded in run.json so results explain themselves).
#pragma once

#include <string>

namespace shelldyn {

std::string sundials_version();

}  // namespace shelldyn
