#pragma once
// The prefix every studio frame shares (docs/studio.md "Frames"): the 4-byte little-endian
// length of the JSON header, the header, zero padding to a multiple of 8, then the body.
// Internal to the command's studio; one file per frame format beside this one.
#include <cstdint>
#include <cstring>
#include <string>
#include <utility>
#include <vector>

namespace clay::recipe::frames {

/// A frame of `body_bytes` after its prefix: the 4-byte little-endian length of the JSON header,
/// the header, zero padding to a multiple of 8. Returns the frame and where the body starts.
/// (Sized once and filled with memcpy: GCC 12 misreads insert() of chars into bytes as an
/// overflow at -O3.)
inline std::pair<std::vector<std::uint8_t>, std::size_t> frame_with_header(
    const std::string& header_json, std::size_t body_bytes) {
  const std::size_t padded = (4 + header_json.size() + 7) / 8 * 8;
  std::vector<std::uint8_t> out(padded + body_bytes, 0);
  const auto length = static_cast<std::uint32_t>(header_json.size());
  for (int k = 0; k < 4; ++k)
    out[static_cast<std::size_t>(k)] = static_cast<std::uint8_t>(length >> (8 * k));
  std::memcpy(out.data() + 4, header_json.data(), header_json.size());
  return {std::move(out), padded};
}

}  // namespace clay::recipe::frames
