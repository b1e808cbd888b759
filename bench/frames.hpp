#pragma once
// The skewed parallelepiped the FFD benchmarks lay their lattices and points in.
#include <clay/deform/lattice.hpp>

namespace clay::bench {

/// A skewed, non-axis-aligned frame of about 300 x 180 x 90 mm.
inline deform::Frame skewed_frame() {
  deform::Frame f;
  f.origin = Eigen::Vector3d(-120.0, 35.0, 10.0);
  f.s = Eigen::Vector3d(300.0, 20.0, -10.0);
  f.t = Eigen::Vector3d(40.0, 180.0, 15.0);
  f.u = Eigen::Vector3d(-10.0, 25.0, 90.0);
  return f;
}

}  // namespace clay::bench
