// A surface's or curve's net as a studio frame (clay/studio.hpp net_frame).
#include "frame_header.hpp"
#include "frames.hpp"

#include <clay/studio.hpp>

#include <cstring>

namespace clay::recipe {

using frames::frame_with_header;

std::vector<std::uint8_t> net_frame(const std::string& header_json,
                                    const std::vector<double>& points,
                                    const std::vector<double>& weights) {
  auto [out, at] =
      frame_with_header(header_json, (points.size() + weights.size()) * sizeof(double));
  // x86-64: little-endian; an empty list (a deviation map has no weights) copies nothing (memcpy
  // may not be handed its null data)
  if (!points.empty()) std::memcpy(out.data() + at, points.data(), points.size() * sizeof(double));
  if (!weights.empty())
    std::memcpy(out.data() + at + points.size() * sizeof(double), weights.data(),
                weights.size() * sizeof(double));
  return out;
}

}  // namespace clay::recipe
