#pragma once
/// Umbrella header of the deform module: FFD lattices (Bézier, Sederberg–Parry 1986; B-spline,
/// Hsu–Hughes–Kaufman 1992), local deformations with continuity, Jacobian bounds and fast
/// deformation of many points (Güdükbay–Özgüç 1990), extended lattices of tricubic chunks
/// (Coquillart 1990), direct manipulation (Hsu–Hughes–Kaufman 1992 §3), Barr's regular
/// deformations (taper, twist, bend), deformation stacks with their JSON form, the style
/// deformation by bound and target curves (Han–De Amicis–Conti 2007), the exact composition of
/// lattices and polynomial tapers with NURBS surfaces (Sederberg–Parry §2.1) and the certified
/// refit of deformed surfaces that are not polynomial, with budgets, light forms (and their linear
/// map in a lattice's points, for drags) and receiver profiles.
#include <clay/deform/compose.hpp>
#include <clay/deform/continuity.hpp>
#include <clay/deform/deformation.hpp>
#include <clay/deform/derivatives.hpp>
#include <clay/deform/direct_manipulation.hpp>
#include <clay/deform/extended_lattice.hpp>
#include <clay/deform/frozen_lattice.hpp>
#include <clay/deform/jacobian.hpp>
#include <clay/deform/lattice.hpp>
#include <clay/deform/light_map.hpp>
#include <clay/deform/model_deformation.hpp>
#include <clay/deform/receiver.hpp>
#include <clay/deform/refit.hpp>
#include <clay/deform/regular.hpp>
#include <clay/deform/stack.hpp>
#include <clay/deform/style.hpp>
#include <clay/deform/surface_deformation.hpp>
#include <clay/surface.hpp>
