// parameter_docs: prints doc/parameters.md, generated from the nodes' parameter registries, or writes it
// with --out. Usage: parameter_docs --help.
#include <fstream>
#include <iostream>
#include <string>

#include "laser_dpslam/common/parameter_docs.h"

namespace {
const char* kUsage =
    "usage: parameter_docs [--out FILE]\n"
    "Prints the parameter reference (doc/parameters.md) generated from the nodes' parameter registries,\n"
    "or writes it to FILE. Regenerate the committed page after changing a registry:\n"
    "  rosrun laser_dpslam parameter_docs --out doc/parameters.md\n";
}  // namespace

int main(int argc, char** argv) {
  std::string out;
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    if (a == "--help" || a == "-h") {
      std::cout << kUsage;
      return 0;
    }
    if (a == "--out" && i + 1 < argc) {
      out = argv[++i];
    } else {
      std::cerr << "parameter_docs: unknown argument '" << a << "'\n" << kUsage;
      return 2;
    }
  }
  const std::string text = laser_dpslam::parametersMarkdown();
  if (out.empty()) {
    std::cout << text;
    return 0;
  }
  std::ofstream file(out);
  file << text;
  if (!file) {
    std::cerr << "parameter_docs: cannot write '" << out << "'\n";
    return 1;
  }
  return 0;
}
