#include "laser_dpslam/scan_preprocessor.h"

namespace laser_dpslam {

PreprocessedScan preprocessScan(const LaserScan& scan, const ScanPreprocessorConfig&) {
  PreprocessedScan out;
  out.stamp = scan.stamp;
  out.error = "not implemented";
  return out;
}

}  // namespace laser_dpslam
