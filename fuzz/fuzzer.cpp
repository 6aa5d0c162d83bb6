// The libFuzzer driver of every target of fuzz/entry_points.hpp, with a
// JSON-aware mutator (fuzz/json_mutator.hpp) beside libFuzzer's own. Compiled
// once; each fuzz_<name> executable links it with a one-line source that defines
// kSweetspotFuzzTarget (the target name: "parse_body", "dispatch", ...).
// A problem aborts with its description, so libFuzzer keeps the input. A note
// (a handler's deliberate 500) aborts too when SWEETSPOT_FUZZ_STRICT=1;
// otherwise it is printed once per kind ("fuzz note: ...") and, when
// SWEETSPOT_FUZZ_NOTES_DIR is set, its first input is saved there.
#include <cctype>
#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <set>
#include <string>
#include <string_view>

#include "fuzz/entry_points.hpp"
#include "fuzz/json_mutator.hpp"

/// The name of the target this executable fuzzes (fuzz/target_name.cpp.in, one per executable).
extern "C" const char kSweetspotFuzzTarget[];

namespace {

using sweetspot::fuzz::Verdict;

// The entry point named kSweetspotFuzzTarget (aborts when there is none).
Verdict (*Entry())(std::string_view) {
  for (const auto& target : sweetspot::fuzz::Targets()) {
    if (std::string_view(target.name) == kSweetspotFuzzTarget) return target.run;
  }
  std::fprintf(stderr, "no fuzz target named %s\n", kSweetspotFuzzTarget);
  std::abort();
}

// The kind of a note: its text without digits, cut to 160 characters.
std::string KindOf(const std::string& note) {
  std::string kind;
  for (const char c : note) {
    if (!std::isdigit(static_cast<unsigned char>(c))) kind.push_back(c);
    if (kind.size() >= 160) break;
  }
  return kind;
}

// Prints a note the first time its kind is seen and saves its input.
void Note(const std::string& note, std::string_view input) {
  static std::set<std::string> seen;
  if (seen.size() >= 64 || !seen.insert(KindOf(note)).second) return;
  std::fprintf(stderr, "fuzz note: %s: %s\n", kSweetspotFuzzTarget, note.c_str());
  if (const char* dir = std::getenv("SWEETSPOT_FUZZ_NOTES_DIR"); dir != nullptr && *dir != '\0') {
    const std::string path = std::string(dir) + "/note-" + std::to_string(seen.size());
    std::ofstream(path, std::ios::binary)
        .write(input.data(), static_cast<std::streamsize>(input.size()));
  }
}

}  // namespace

/// libFuzzer's byte-level mutator (with the -dict words).
extern "C" std::size_t LLVMFuzzerMutate(std::uint8_t* data, std::size_t size, std::size_t max_size);

/// libFuzzer's mutation hook: half the time a JSON-aware change, else libFuzzer's own.
extern "C" std::size_t LLVMFuzzerCustomMutator(std::uint8_t* data, std::size_t size,
                                               std::size_t max_size, unsigned int seed) {
  if (seed % 2 == 0) {
    if (const std::size_t n = sweetspot::fuzz::MutateJson(data, size, max_size, seed); n > 0) {
      return n;
    }
  }
  return LLVMFuzzerMutate(data, size, max_size);
}

/// libFuzzer's entry: one input through the target; abort on a problem.
extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  static const auto run = Entry();
  static const bool strict = [] {
    const char* value = std::getenv("SWEETSPOT_FUZZ_STRICT");
    return value != nullptr && std::string_view(value) == "1";
  }();
  const std::string_view input(reinterpret_cast<const char*>(data), size);
  const Verdict verdict = run(input);
  if (!verdict.problem.empty() || (strict && !verdict.note.empty())) {
    std::fprintf(stderr, "fuzz problem: %s: %s\n", kSweetspotFuzzTarget,
                 verdict.problem.empty() ? verdict.note.c_str() : verdict.problem.c_str());
    std::abort();
  }
  if (!verdict.note.empty()) Note(verdict.note, input);
  return 0;
}
