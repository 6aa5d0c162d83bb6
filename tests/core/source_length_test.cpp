// No source file over 600 lines and no function over 120 in core/, api/ and server/ (issue 33
// item 6). A file's lines are its newlines. A function's lines
// are counted from the first line of its declaration to its closing brace, as Universal Ctags
// counts them (end - start, but from a template clause's line rather than the name's: at most
// a line or two more; the command is in docs/architecture.md, "Build and style"). The
// scan reads C++ as far as braces go: comments, string, character and raw string literals and
// preprocessor lines are skipped; a brace block at namespace or class scope whose head has a
// parameter list is a function (its lambdas counted in it); namespaces, classes, enums and
// initialisers (an '=' before the first '(') are not. A file whose braces do not balance fails,
// so the scan cannot silently misread one.
#include <gtest/gtest.h>

#include <algorithm>
#include <cctype>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <utility>
#include <vector>

namespace sweetspot::core {
namespace source_length_test {
namespace {

namespace fs = std::filesystem;

constexpr int kMaxFunctionLines = 120;
constexpr int kMaxFileLines = 600;

// A function found by the scan: its head (the declaration, whitespace collapsed) and its lines
// (first line of the head, closing brace; 1-based).
struct FunctionSpan {
  std::string head;
  int start = 0;
  int end = 0;
};

// An open brace block: whether it is a scope whose blocks may be functions (a namespace, a
// class, an extern "C"), whether it is a function, its head and first line.
struct OpenBlock {
  bool scope = false;
  bool function = false;
  std::string head;
  int start = 0;
};

std::string Collapse(const std::string& text) {
  std::string out;
  for (char c : text) {
    if (std::isspace(static_cast<unsigned char>(c))) {
      if (!out.empty() && out.back() != ' ') out += ' ';
    } else {
      out += c;
    }
  }
  while (!out.empty() && out.back() == ' ') out.pop_back();
  return out;
}

// The head without leading "template <...>" clauses.
std::string WithoutTemplate(std::string head) {
  while (head.rfind("template", 0) == 0) {
    const auto open = head.find('<');
    if (open == std::string::npos) break;
    int depth = 0;
    std::size_t i = open;
    for (; i < head.size(); ++i) {
      if (head[i] == '<') ++depth;
      if (head[i] == '>' && --depth == 0) break;
    }
    head = Collapse(head.substr(std::min(i + 1, head.size())));
  }
  return head;
}

bool StartsWithWord(const std::string& text, const char* word) {
  const std::string w(word);
  return text.rfind(w, 0) == 0 &&
         (text.size() == w.size() ||
          !(std::isalnum(static_cast<unsigned char>(text[w.size()])) || text[w.size()] == '_'));
}

// A scope whose blocks may be functions: a namespace, a class, struct or union, extern "C".
bool IsScopeHead(const std::string& head) {
  const std::string h = WithoutTemplate(head);
  for (const char* word : {"namespace", "struct", "class", "union", "extern"}) {
    if (StartsWithWord(h, word)) return true;
  }
  return h.rfind("typedef struct", 0) == 0;
}

// A function's head: a parameter list, not an enum, not an initialiser or an assigned lambda
// (an '=' before the first '(', except in an operator's name).
bool IsFunctionHead(const std::string& head) {
  const std::string h = WithoutTemplate(head);
  if (h.empty() || StartsWithWord(h, "enum")) return false;
  const auto paren = h.find('(');
  if (paren == std::string::npos) return false;
  const auto equals = h.find('=');
  return equals > paren || h.find("operator") < equals;
}

// Every function of `text` (see the file's comment); *balanced false when its braces do not
// balance.
std::vector<FunctionSpan> FunctionsIn(const std::string& text, bool* balanced) {
  std::vector<FunctionSpan> out;
  std::vector<OpenBlock> stack;
  std::string head;    // the code since the last statement boundary at the current depth
  int head_start = 0;  // its first line
  int line = 1;
  bool line_start = true;  // only whitespace so far on this line
  *balanced = true;
  const std::size_t n = text.size();
  auto in_scope = [&] { return stack.empty() || stack.back().scope; };
  for (std::size_t i = 0; i < n; ++i) {
    const char c = text[i];
    if (c == '\n') {
      ++line;
      line_start = true;
      if (!head.empty()) head += ' ';
      continue;
    }
    if (line_start && c == '#') {  // a preprocessor line, with its continuations
      while (i < n && !(text[i] == '\n' && text[i - 1] != '\\')) {
        if (text[i] == '\n') ++line;
        ++i;
      }
      --i;
      continue;
    }
    if (!std::isspace(static_cast<unsigned char>(c))) line_start = false;
    if (c == '/' && i + 1 < n && text[i + 1] == '/') {
      while (i + 1 < n && text[i + 1] != '\n') ++i;
      continue;
    }
    if (c == '/' && i + 1 < n && text[i + 1] == '*') {
      i += 2;
      while (i + 1 < n && !(text[i] == '*' && text[i + 1] == '/')) {
        if (text[i] == '\n') ++line;
        ++i;
      }
      ++i;
      continue;
    }
    const bool ident_before =
        i > 0 && (std::isalnum(static_cast<unsigned char>(text[i - 1])) || text[i - 1] == '_');
    if (c == '"' && i > 0 && text[i - 1] == 'R') {  // a raw string: R"delim( ... )delim"
      const auto open = text.find('(', i);
      const std::string close = ")" + text.substr(i + 1, open - i - 1) + "\"";
      const auto end = text.find(close, open);
      for (std::size_t k = i; k < end && k < n; ++k) {
        if (text[k] == '\n') ++line;
      }
      i = end == std::string::npos ? n : end + close.size() - 1;
      head += "\"\"";
      continue;
    }
    if (c == '"' ||
        (c == '\'' &&
         !(ident_before && std::isxdigit(static_cast<unsigned char>(text[i - 1]))))) {  // not 1'000
      for (++i; i < n && text[i] != c; ++i) {
        if (text[i] == '\\') ++i;
      }
      head += "\"\"";
      continue;
    }
    if (c == '{') {
      OpenBlock block;
      block.head = Collapse(head);
      block.start = head_start > 0 ? head_start : line;
      if (in_scope()) {
        block.scope = IsScopeHead(block.head);
        block.function = !block.scope && IsFunctionHead(block.head);
      }
      stack.push_back(block);
      head.clear();
      head_start = 0;
      continue;
    }
    if (c == '}') {
      if (stack.empty()) {
        *balanced = false;
        return out;
      }
      const OpenBlock block = stack.back();
      stack.pop_back();
      if (block.function) out.push_back({block.head, block.start, line});
      head.clear();
      head_start = 0;
      continue;
    }
    if (c == ';') {
      head.clear();
      head_start = 0;
      continue;
    }
    if (std::isspace(static_cast<unsigned char>(c))) {
      if (!head.empty()) head += ' ';
    } else {
      if (head_start == 0) head_start = line;
      head += c;
    }
  }
  if (!stack.empty()) *balanced = false;
  return out;
}

std::string ReadFile(const fs::path& path) {
  std::ifstream in(path);
  std::ostringstream text;
  text << in.rdbuf();
  return text.str();
}

// The C++ sources under `folders` (relative to the source tree), each with its path there.
std::vector<std::pair<std::string, fs::path>> SourcesUnder(
    const std::vector<std::string>& folders) {
  std::vector<std::pair<std::string, fs::path>> out;
  const fs::path root(SWEETSPOT_SOURCE_DIR);
  for (const std::string& folder : folders) {
    for (const auto& entry : fs::recursive_directory_iterator(root / folder)) {
      const auto ext = entry.path().extension();
      if (ext != ".hpp" && ext != ".cpp" && ext != ".h") continue;
      out.emplace_back(fs::relative(entry.path(), root).generic_string(), entry.path());
    }
  }
  return out;
}

// "file:line head (N lines)" for each function of the sources under `folders` longer than
// kMaxFunctionLines, and each file the scan cannot balance; *functions: how many it found.
std::vector<std::string> LongFunctions(const std::vector<std::string>& folders, int* functions) {
  std::vector<std::string> out;
  *functions = 0;
  for (const auto& [file, path] : SourcesUnder(folders)) {
    bool balanced = true;
    for (const FunctionSpan& f : FunctionsIn(ReadFile(path), &balanced)) {
      ++*functions;
      if (f.end - f.start > kMaxFunctionLines) {
        out.push_back(file + ":" + std::to_string(f.start) + " " + f.head.substr(0, 100) + " (" +
                      std::to_string(f.end - f.start) + " lines)");
      }
    }
    if (!balanced) out.push_back(file + ": braces do not balance (the scan cannot read it)");
  }
  return out;
}

TEST(FunctionLengthTest, ScanFindsFunctionsAndSkipsWhatIsNot) {
  // A function with braces in literals and comments, a lambda, a class with a member function,
  // an initialiser, an enum, a macro and a namespace: the function and the member, with lines.
  const std::string text =
      "namespace a {\n"                                       // 1
      "// { not code\n"                                       // 2
      "template <class T>\n"                                  // 3
      "int F(int x = 1) {\n"                                  // 4
      "  const char* s = \"}{\"; char c = '}';\n"             // 5
      "  auto g = [&] { return 1'000; };\n"                   // 6
      "  return x;\n"                                         // 7
      "}\n"                                                   // 8
      "struct S {\n"                                          // 9
      "  bool operator==(const S&) const { return true; }\n"  // 10
      "};\n"                                                  // 11
      "const int kT[] = {1, 2};\n"                            // 12
      "enum class E { kA, kB };\n"                            // 13
      "#define M(x) { x\n"                                    // 14
      "}  // namespace a\n";                                  // 15
  bool balanced = false;
  const std::vector<FunctionSpan> found = FunctionsIn(text, &balanced);
  EXPECT_TRUE(balanced);
  ASSERT_EQ(found.size(), 2u);
  EXPECT_EQ(found[0].start, 3);  // from its template clause (ctags: from its name, line 4)
  EXPECT_EQ(found[0].end, 8);
  EXPECT_EQ(found[1].start, 10);
  EXPECT_EQ(found[1].end, 10);
  EXPECT_NE(found[1].head.find("operator=="), std::string::npos);
}

TEST(FunctionLengthTest, ScanMeasuresALongFunctionAndRefusesUnbalancedBraces) {
  // A function of 121 lines (head to closing brace: 120 statements between) is over the limit.
  std::string text = "void Long() {\n";
  for (int i = 0; i < 120; ++i) text += "  ++n;\n";
  text += "}\n";
  bool balanced = false;
  const std::vector<FunctionSpan> found = FunctionsIn(text, &balanced);
  EXPECT_TRUE(balanced);
  ASSERT_EQ(found.size(), 1u);
  EXPECT_EQ(found[0].end - found[0].start, 121);
  EXPECT_GT(found[0].end - found[0].start, kMaxFunctionLines);
  FunctionsIn("void F() {\n  if (x) {\n}\n", &balanced);
  EXPECT_FALSE(balanced);
}

TEST(FunctionLengthTest, NoFunctionInCoreApiOrServerIsLongerThan120Lines) {
  int functions = 0;
  for (const std::string& f : LongFunctions({"core", "api", "server"}, &functions)) {
    ADD_FAILURE() << f;
  }
  EXPECT_GT(functions, 1000);  // the functions were found (a blind scan would pass vacuously)
}

TEST(FileLengthTest, NoSourceFileInCoreApiOrServerIsLongerThan600Lines) {
  int files = 0;
  for (const auto& [file, path] : SourcesUnder({"core", "api", "server"})) {
    const std::string text = ReadFile(path);
    const auto lines = std::count(text.begin(), text.end(), '\n');
    EXPECT_LE(lines, kMaxFileLines) << file << " has " << lines << " lines: split it by concept";
    ++files;
  }
  EXPECT_GT(files, 100);  // the sources were found (a wrong root would pass vacuously)
}

}  // namespace
}  // namespace source_length_test
}  // namespace sweetspot::core
