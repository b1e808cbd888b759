#pragma once
// Internal to clay_deform: an extended lattice as a point map for the refit, prepared once.
#include <clay/deform/extended_lattice.hpp>

#include <functional>

namespace clay::deform::detail {

/// x -> deform_point(lattice, x), bit for bit, but with the lattice's chunk data and search grid
/// prepared once (deform_point prepares them per call, which dominated refits of extended
/// lattices: one call per sample). Safe to call from several threads. Throws like freeze() for
/// an invalid lattice (here) or a non-finite point (per call).
std::function<Eigen::Vector3d(const Eigen::Vector3d&)> prepared_point_map(
    const ExtendedLattice& lattice);

}  // namespace clay::deform::detail
