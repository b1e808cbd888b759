// libFuzzer target: clay::recipe::StudioSession::handle, the studio's command handling, on
// arbitrary bytes (issue #36: one message ended the server). Its contract (clay/studio.hpp):
// nothing a command holds makes it throw, every reply is a JSON object with "op" in valid UTF-8,
// and a refused command changes nothing. Each input runs on a fresh session of a small recipe
// (a skinned patch with a Bézier lattice) in a scratch folder of its own, so saves and exports
// the fuzzer finds stay there.
#include <clay/studio.hpp>

#include <nlohmann/json.hpp>

#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <exception>
#include <filesystem>
#include <string>

#include "fuzz_traps.hpp"

namespace {

const char* const recipe = R"({
 "format": "clayform.recipe", "version": 1, "name": "fuzz",
 "curves": {
  "a": {"line": {"from": [0, 0, 0], "to": [100, 0, 0]}},
  "b": {"line": {"from": [0, 60, 10], "to": [100, 60, 10]}}
 },
 "surfaces": {
  "patch": {"skin": {"sections": ["a", "b"], "degree": 1}},
  "bent": {"deform": {"surface": "patch", "deformation": "bulge"}}
 },
 "deformations": {
  "bulge": [{"kind": "bezier_lattice", "degrees": [1, 1, 1],
             "frame": {"origin": [-1, -1, -5], "s": [102, 0, 0], "t": [0, 62, 0], "u": [0, 0, 20]},
             "moves": [{"index": [1, 1, 1], "by": [0, 0, 5]}]}]
 }
})";

std::filesystem::path scratch;

}  // namespace

extern "C" int LLVMFuzzerInitialize(int*, char***) {
  clay::fuzz::enable_traps();
  std::string pattern = (std::filesystem::temp_directory_path() / "clayform-fuzz-studio-XXXXXX");
  if (!::mkdtemp(pattern.data())) std::abort();
  scratch = pattern;
  std::atexit([] {
    std::error_code ec;
    std::filesystem::remove_all(scratch, ec);
  });
  return 0;
}

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string command(reinterpret_cast<const char*>(data), size);
  try {
    clay::recipe::StudioSession session(recipe, scratch, "fuzz");
    const std::string before = session.text();
    const auto reply = session.handle(command);
    const auto parsed = nlohmann::json::parse(reply.json);  // throws on invalid UTF-8
    if (!parsed.is_object() || !parsed.contains("op") || !parsed.at("op").is_string()) {
      std::fprintf(stderr, "a reply without \"op\": %s\n", reply.json.c_str());
      std::abort();
    }
    if (parsed.at("op") == "error" && (session.text() != before || session.history().size() != 1)) {
      std::fprintf(stderr, "a refused command changed the session: %s\n", reply.json.c_str());
      std::abort();
    }
  } catch (const std::exception& e) {
    std::fprintf(stderr, "the studio session threw: %s\n", e.what());
    std::abort();
  }
  return 0;
}
