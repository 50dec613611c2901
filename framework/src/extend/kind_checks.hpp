#pragma once
// The conformance checks of each plugin kind (conformance.cpp), for the table of plugin kinds (plugin_kinds.cpp).
#include <string>
#include <vector>

#include "redres/extend/conformance.hpp"

namespace redres::kind_checks {

void objectives(const std::string& origin, std::vector<ConformanceResult>& out);
void constraints(const std::string& origin, std::vector<ConformanceResult>& out);
void tasks(const std::string& origin, std::vector<ConformanceResult>& out);
void velocity_limits(const std::string& origin, std::vector<ConformanceResult>& out);
void paths(const std::string& origin, std::vector<ConformanceResult>& out);
void engines(const std::string& origin, std::vector<ConformanceResult>& out);

}  // namespace redres::kind_checks
