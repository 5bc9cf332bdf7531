// Words of one line of the package's plain-text inputs (waypoint files, geometry plans): what follows a
// '#' is a comment, words are separated by white space. No ROS.
#pragma once

#include <sstream>
#include <string>
#include <vector>

namespace laser_dpslam {

/// The white-space separated words of `line` before any '#'; empty for a blank or comment line.
inline std::vector<std::string> lineWords(std::string line) {
  const std::size_t hash = line.find('#');
  if (hash != std::string::npos) line.erase(hash);
  std::istringstream tokens(line);
  std::vector<std::string> words;
  for (std::string w; tokens >> w;) words.push_back(w);
  return words;
}

}  // namespace laser_dpslam
