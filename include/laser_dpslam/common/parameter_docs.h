// doc/parameters.md, generated from the two nodes' parameter registries (tool parameter_docs; a test keeps
// the committed file equal to it).
#pragma once

#include <string>

namespace laser_dpslam {

/// The whole of doc/parameters.md.
std::string parametersMarkdown();

}  // namespace laser_dpslam
