#pragma once
// The run report (pipeline/run_report.h) as the command line prints it.
#include <string>

#include "pipeline/run_report.h"

namespace nebula::app {

// What was rendered, then "computed, and why" line by line, then the timing.
void print_report(const RunReport& report);

}  // namespace nebula::app
