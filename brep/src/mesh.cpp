// Checking MeshOptions (clay/brep/mesh.hpp); the mesher is the OCCT library's.
#include <clay/brep/mesh.hpp>
#include <clay/error.hpp>
#include <clay/internal/checks.hpp>
#include <clay/internal/format.hpp>

#include <string>
#include <vector>

namespace clay::brep {

using internal::shortest;

std::vector<std::string> MeshOptions::problems() const {
  std::vector<std::string> out;
  if (!(relative_deflection >= 1e-6 && relative_deflection <= 0.1))
    out.push_back("MeshOptions::relative_deflection = " + shortest(relative_deflection) +
                  " must be in [1e-6, 0.1] (a fraction of the model's size)");
  if (!(angular_deflection_rad >= 0.01 && angular_deflection_rad <= 1))
    out.push_back("MeshOptions::angular_deflection_rad = " + shortest(angular_deflection_rad) +
                  " must be in [0.01, 1] radians");
  return out;
}

void MeshOptions::validate() const {
  const auto list = problems();
  if (!list.empty()) internal::throw_problems(ErrorCategory::InvalidArgument, list);
}

}  // namespace clay::brep
