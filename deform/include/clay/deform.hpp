#pragma once
/// Umbrella header of the deform module: FFD lattices (Bézier, Sederberg–Parry 1986; B-spline,
/// Hsu–Hughes–Kaufman 1992), local deformations with continuity, Jacobian bounds and fast
/// deformation of many points (Güdükbay–Özgüç 1990), extended lattices of tricubic chunks
/// (Coquillart 1990). Style deformation, direct manipulation, regular deformations and stacks
/// arrive with issues #5-#7.
#include <clay/constraints.hpp>
#include <clay/deform/continuity.hpp>
#include <clay/deform/deformation.hpp>
#include <clay/deform/extended_lattice.hpp>
#include <clay/deform/frozen_lattice.hpp>
#include <clay/deform/jacobian.hpp>
#include <clay/deform/lattice.hpp>
