// One refusal form (core/refusal.hpp): every validator of core, the api and the server is
// `bool Validate(Refusal*) const`, and no message is read back by its text. Scans the sources,
// as the layering test scans the #include lines, so that a string-form validator
// (`IsValid(std::string*)`) or a message read back by prefix fails the tests.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <regex>
#include <string>
#include <vector>

namespace sweetspot::core {
// In a namespace of its own: the test programs are unity builds (cmake/BuildSpeed.cmake).
namespace refusal_form_test {
namespace {

namespace fs = std::filesystem;

struct Hit {
  std::string file;
  int line = 0;
  std::string text;
};

// The lines of the sources under `folder` that match `pattern`.
std::vector<Hit> Matches(const std::string& folder, const std::regex& pattern) {
  std::vector<Hit> out;
  const fs::path root = fs::path(SWEETSPOT_SOURCE_DIR) / folder;
  for (const auto& entry : fs::recursive_directory_iterator(root)) {
    const auto ext = entry.path().extension();
    if (ext != ".hpp" && ext != ".cpp" && ext != ".h") continue;
    std::ifstream in(entry.path());
    std::string line;
    int number = 0;
    while (std::getline(in, line)) {
      ++number;
      if (std::regex_search(line, pattern)) out.push_back({entry.path().string(), number, line});
    }
  }
  return out;
}

TEST(RefusalFormTest, NoValidatorWritesAString) {
  const std::regex string_form(R"(IsValid\s*\(\s*(const\s+)?std::string\s*\*)");
  for (const char* folder : {"core", "api", "server"}) {
    for (const Hit& h : Matches(folder, string_form)) {
      ADD_FAILURE() << h.file << ":" << h.line << ": " << h.text
                    << "\n  validators refuse as data: bool Validate(Refusal*) const";
    }
  }
}

TEST(RefusalFormTest, NoMessageIsReadBackByItsText) {
  // A message or a refusal's text searched for a prefix or a phrase ("message.rfind(",
  // "why.find("): code tells outcomes apart by a kind (ConflictKind, DesignMessageKind).
  const std::regex read_back(R"(\b(message|why|message\(\))\s*\.\s*r?find\s*\()");
  for (const char* folder : {"core", "api", "server"}) {
    for (const Hit& h : Matches(folder, read_back)) {
      ADD_FAILURE() << h.file << ":" << h.line << ": " << h.text;
    }
  }
}

}  // namespace
}  // namespace refusal_form_test
}  // namespace sweetspot::core
