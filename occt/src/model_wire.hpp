#pragma once
// The isolated read's answer (model_wire.cpp): an ImportedModel packed into bytes by the child
// process that reads a file, and unpacked by the parent (surface::occt::read_in_child). Internal
// to the OCCT library.
#include <clay/occt/model_exchange.hpp>

#include <string>

namespace clay::brep::detail {

/// The model, its report and its names, colours and assembly, as bytes.
std::string serialize(const ImportedModel& x);

/// Reads back what serialize wrote; counts, gaps and problems are computed again here, from the
/// model.
ImportedModel deserialize(const std::string& bytes);

/// The figures that depend only on the model: counts, the largest edge gap and the problems.
void complete_report(ImportedModel& x);

}  // namespace clay::brep::detail
