#pragma once
// Cheap text checks of STEP and IGES files before OpenCASCADE reads them (internal; see
// ReadOptions::precheck in clay/occt/surface_exchange.hpp). OpenCASCADE 7.6 crashes or hangs on
// some malformed files instead of reporting them (issue #18: a single dangling `#n` reference
// crashed StepToGeom::MakeCartesianPoint; NaN or infinite coordinates and degree 99 hung it);
// these scans refuse the known triggers with the entity and line. Denormal numbers, refused at
// first, are read (issue #39): OpenCASCADE and FreeCAD read them, and Alibre writes them. The
// scans are a first line only: the isolated read (a child process) catches what they miss.
#include <cstddef>
#include <filesystem>
#include <string_view>

namespace clay::surface::detail {

/// Largest magnitude a number in an exchange file may have; beyond it no geometry is meant.
inline constexpr double max_file_number = 1e100;

/// Most entries a list of a STEP entity may have (a shell of 50,000 faces; a B-spline's rows are
/// far shorter): OpenCASCADE took past the reader's time limit on a list of 10^5 references.
inline constexpr std::size_t max_list_entries = 50000;

/// Checks a STEP (ISO 10303-21) file in one pass over its text: every `#n` reference in the DATA
/// section names an entity the file defines, and no entity number is defined twice; no list has
/// more than max_list_entries entries; every number is finite and at most
/// max_file_number in magnitude; bare words are only entity names (so `NaN` and `INF` are
/// refused); B-spline curve and surface degrees are integers in [1, max_degree]; parentheses
/// balance and strings end. Throws clay::Error(Exchange) "CALLER: 'FILE' line L, entity #N: ..."
/// for the first problem found (a dangling reference: the first in file order).
void precheck_step(const std::filesystem::path& file, std::string_view caller, int max_degree);

/// Checks an IGES file: its parameter data numbers as precheck_step, and each rational B-spline
/// curve (126) and surface (128) record: degrees in [1, max_degree], upper indices >= degree and
/// enough parameters for the counts they declare. Throws clay::Error(Exchange) "CALLER: 'FILE'
/// line L, entity TYPE (directory entry D): ..." for the first problem found.
void precheck_iges(const std::filesystem::path& file, std::string_view caller, int max_degree);

}  // namespace clay::surface::detail
