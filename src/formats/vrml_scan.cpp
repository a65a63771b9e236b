// The pre-scan of VRML97 text (see vrml_scan.hpp). A structural walk over tokens: it knows
// where nodes, fields, values, PROTOs and ROUTEs start and end, but builds nothing; Coin3D
// reads the file afterwards. Its job is to turn every input that would crash or hang Coin
// into a `file:line:column:` message, and to give drape's own nodes their source lines.

#include "drape/formats/vrml_scan.hpp"

#include <algorithm>
#include <set>

#include <fmt/format.h>

#include "drape/core/error.hpp"

namespace drape::formats::vrml {
namespace {

constexpr std::string_view kHeader = "#VRML V2.0 utf8";

enum class Tok { End, Id, Number, String, OpenBrace, CloseBrace, OpenBracket, CloseBracket };

struct Token {
  Tok kind = Tok::End;
  std::string_view text;
  std::size_t offset = 0;
  int line = 0;
  int column = 0;
};

bool isSpace(unsigned char c) { return c == ' ' || c == '\t' || c == '\n' || c == '\r' || c == ','; }
bool isControl(unsigned char c) { return (c < 0x20 && c != '\t' && c != '\n' && c != '\r') || c == 0x7f; }
bool endsWord(unsigned char c) {
  return isSpace(c) || isControl(c) || c == '"' || c == '#' || c == '{' || c == '}' || c == '[' || c == ']' ||
         c == '\'' || c == '\\';
}
bool startsNumber(std::string_view s) {
  const unsigned char c = static_cast<unsigned char>(s[0]);
  if (c >= '0' && c <= '9') return true;
  if ((c == '+' || c == '-' || c == '.') && s.size() > 1) {
    const unsigned char d = static_cast<unsigned char>(s[1]);
    return (d >= '0' && d <= '9') || (d == '.' && c != '.');
  }
  return false;
}

class Lexer {
 public:
  Lexer(std::string_view text, const std::string& file) : text_(text), file_(file) {}

  [[noreturn]] void fail(int line, int column, const std::string& what) const {
    throw Error::at({file_, line, column}, what);
  }

  Token next() {
    skipSpaceAndComments();
    Token t;
    t.offset = pos_;
    t.line = line_;
    t.column = column();
    if (pos_ >= text_.size()) return t;
    const unsigned char c = static_cast<unsigned char>(text_[pos_]);
    switch (c) {
      case '{':
        t.kind = Tok::OpenBrace;
        break;
      case '}':
        t.kind = Tok::CloseBrace;
        break;
      case '[':
        t.kind = Tok::OpenBracket;
        break;
      case ']':
        t.kind = Tok::CloseBracket;
        break;
      default:
        break;
    }
    if (t.kind != Tok::End) {
      t.text = text_.substr(pos_, 1);
      advance(1);
      return t;
    }
    if (c == '"') return string(t);
    if (c == '\'' || c == '\\') fail(t.line, t.column, fmt::format("unexpected character '{}'", static_cast<char>(c)));
    std::size_t end = pos_;
    while (end < text_.size() && !endsWord(static_cast<unsigned char>(text_[end]))) ++end;
    t.text = text_.substr(pos_, end - pos_);
    t.kind = startsNumber(t.text) ? Tok::Number : Tok::Id;
    advance(end - pos_);
    return t;
  }

 private:
  int column() const { return static_cast<int>(pos_ - lineStart_) + 1; }

  void advance(std::size_t n) {
    for (std::size_t i = 0; i < n; ++i, ++pos_) {
      if (text_[pos_] == '\n') {
        ++line_;
        lineStart_ = pos_ + 1;
      }
    }
  }

  void skipSpaceAndComments() {
    while (pos_ < text_.size()) {
      const unsigned char c = static_cast<unsigned char>(text_[pos_]);
      if (isSpace(c)) {
        advance(1);
      } else if (c == '#') {
        while (pos_ < text_.size() && text_[pos_] != '\n') {
          if (text_[pos_] == '\0') fail(line_, column(), "unexpected NUL byte");
          ++pos_;
        }
      } else if (isControl(c)) {
        fail(line_, column(), fmt::format("unexpected byte 0x{:02x}", c));
      } else {
        return;
      }
    }
  }

  Token string(Token t) {
    std::size_t end = pos_ + 1;
    while (end < text_.size() && text_[end] != '"') {
      if (text_[end] == '\0') fail(t.line, t.column, "NUL byte inside a string");
      end += text_[end] == '\\' ? 2 : 1;
    }
    if (end >= text_.size()) fail(t.line, t.column, "unterminated string (no closing '\"')");
    t.kind = Tok::String;
    t.text = text_.substr(pos_, end + 1 - pos_);
    advance(end + 1 - pos_);
    return t;
  }

  std::string_view text_;
  const std::string& file_;
  std::size_t pos_ = 0;
  std::size_t lineStart_ = 0;
  int line_ = 1;
};

struct Scope {
  std::set<std::string, std::less<>> defs;
  std::vector<std::string> openDefs;  ///< DEF names whose node is still open
};

class Scanner {
 public:
  Scanner(std::string_view text, const std::string& file, const ScanOptions& options)
      : text_(text), options_(options), lexer_(text, file) {
    for (const ProtoInterface& p : options.knownProtos) protos_[p.name] = {p, true};
    current_ = lexer_.next();
  }

  ScanResult run() {
    scopes_.emplace_back();
    while (current_.kind != Tok::End) statement();
    return finish();
  }

 private:
  struct Known {
    ProtoInterface interface;
    bool fromPrelude = false;
  };

  [[noreturn]] void fail(const Token& t, const std::string& what) const { lexer_.fail(t.line, t.column, what); }

  static std::string describe(const Token& t) {
    if (t.kind == Tok::End) return "the end of the file";
    std::string s(t.text.substr(0, 40));
    return fmt::format("'{}'", s);
  }

  Token take() {
    Token t = current_;
    current_ = lexer_.next();
    return t;
  }
  bool isId(std::string_view word) const { return current_.kind == Tok::Id && current_.text == word; }
  Token expect(Tok kind, const char* what) {
    if (current_.kind != kind) fail(current_, fmt::format("expected {}, found {}", what, describe(current_)));
    return take();
  }
  Token expectName(const char* what) {
    const Token t = expect(Tok::Id, what);
    if (t.text.find('.') != std::string_view::npos) fail(t, fmt::format("expected {}, found {}", what, describe(t)));
    return t;
  }

  void open(const Token& t) {
    if (++depth_ > options_.maxDepth)
      fail(t, fmt::format("nesting deeper than {} levels (drape's limit for VRML97 files)", options_.maxDepth));
  }
  void close() { --depth_; }

  // statement: PROTO | EXTERNPROTO | ROUTE | node
  void statement() {
    if (isId("PROTO")) return proto();
    if (isId("EXTERNPROTO")) return externProto();
    if (isId("ROUTE")) return route();
    node();
  }

  void proto() {
    const Token keyword = take();
    const Token name = expectName("a PROTO name");
    ProtoInterface interface { std::string(name.text), {}, keyword.line, false };
    scopes_.emplace_back();
    bodyTypes_.emplace_back();
    open(expect(Tok::OpenBracket, "'[' after the PROTO name"));
    while (current_.kind != Tok::CloseBracket) {
      const Token kind = expect(Tok::Id, "a field declaration or ']'");
      const bool hasValue = kind.text == "field" || kind.text == "exposedField";
      if (!hasValue && kind.text != "eventIn" && kind.text != "eventOut")
        fail(kind, fmt::format("expected field, exposedField, eventIn or eventOut, found {}", describe(kind)));
      expectName("a field type");
      const Token field = expectName("a field name");
      interface.fields.emplace_back(field.text);
      if (hasValue) value(field.text);
    }
    take();
    close();
    open(expect(Tok::OpenBrace, "'{' (the PROTO body)"));
    while (current_.kind != Tok::CloseBrace) {
      if (current_.kind == Tok::End)
        fail(current_, fmt::format("unexpected end of file in PROTO {} (missing '}}')", name.text));
      statement();
    }
    take();
    close();
    scopes_.pop_back();
    checkRecursion(name, std::move(bodyTypes_.back()));
    bodyTypes_.pop_back();
    declare(std::move(interface));
  }

  /// A PROTO whose instances contain, directly or through other PROTOs, an instance of
  /// itself: Coin expands it without end and overflows its stack.
  void checkRecursion(const Token& name, std::set<std::string, std::less<>> used) {
    std::vector<std::string> work(used.begin(), used.end());
    while (!work.empty()) {
      const std::string type = work.back();
      work.pop_back();
      const auto it = protoUses_.find(type);
      if (it == protoUses_.end()) continue;
      for (const std::string& t : it->second)
        if (used.insert(t).second) work.push_back(t);
    }
    if (used.contains(name.text))
      fail(name, fmt::format("PROTO {} contains an instance of itself (directly or through other PROTOs)", name.text));
    protoUses_[std::string(name.text)] = std::move(used);
  }

  void externProto() {
    const Token keyword = take();
    const Token name = expectName("an EXTERNPROTO name");
    ProtoInterface interface { std::string(name.text), {}, keyword.line, true };
    open(expect(Tok::OpenBracket, "'[' after the EXTERNPROTO name"));
    while (current_.kind != Tok::CloseBracket) {
      const Token kind = expect(Tok::Id, "a field declaration or ']'");
      if (kind.text != "field" && kind.text != "exposedField" && kind.text != "eventIn" && kind.text != "eventOut")
        fail(kind, fmt::format("expected field, exposedField, eventIn or eventOut, found {}", describe(kind)));
      expectName("a field type");
      interface.fields.emplace_back(expectName("a field name").text);
    }
    take();
    close();
    urls();
    declare(std::move(interface));
  }

  void urls() {
    if (current_.kind == Tok::String) {
      take();
      return;
    }
    open(expect(Tok::OpenBracket, "the EXTERNPROTO's URL (a string or a list of strings)"));
    while (current_.kind == Tok::String) take();
    expect(Tok::CloseBracket, "a URL string or ']'");
    close();
  }

  void declare(ProtoInterface interface) {
    const std::string name = interface.name;
    result_.declared.push_back(interface);
    protos_[name] = {std::move(interface), false};
  }

  void route() {
    take();
    const Token from = expect(Tok::Id, "'node.eventOut' after ROUTE");
    routeEnd(from);
    const Token to = expect(Tok::Id, "TO");
    if (to.text != "TO") fail(to, fmt::format("expected TO, found {}", describe(to)));
    routeEnd(expect(Tok::Id, "'node.eventIn' after TO"));
  }

  void routeEnd(const Token& t) {
    const std::size_t dot = t.text.find('.');
    if (dot == std::string_view::npos || dot == 0 || dot + 1 == t.text.size())
      fail(t, fmt::format("expected 'node.event' in ROUTE, found {}", describe(t)));
    const std::string_view node = t.text.substr(0, dot);
    if (!scopes_.back().defs.contains(node))
      fail(t, fmt::format("ROUTE names '{}', which no DEF before it declares", node));
  }

  // node: DEF name Type { body } | USE name | Type { body } | NULL
  void node() {
    if (isId("USE")) return use();
    if (isId("NULL")) {
      take();
      return;
    }
    std::string def;
    if (isId("DEF")) {
      take();
      def = std::string(expectName("a name after DEF").text);
    }
    const Token type = expectName("a node type");
    for (auto& used : bodyTypes_) used.emplace(type.text);
    if (type.text == "DEF" || type.text == "USE" || type.text == "PROTO" || type.text == "ROUTE")
      fail(type, fmt::format("expected a node type, found {}", describe(type)));
    Scope& scope = scopes_.back();
    if (!def.empty()) {
      scope.defs.insert(def);
      scope.openDefs.push_back(def);
    }
    const Token brace = expect(Tok::OpenBrace, fmt::format("'{{' after the node type {}", type.text).c_str());
    open(brace);
    body(type, def, brace);
    close();
    if (!def.empty()) scopes_.back().openDefs.pop_back();
  }

  void use() {
    take();
    const Token name = expectName("a name after USE");
    const Scope& scope = scopes_.back();
    if (std::find(scope.openDefs.begin(), scope.openDefs.end(), name.text) != scope.openDefs.end())
      fail(name, fmt::format("USE {} inside its own DEF {} (a node cannot contain itself)", name.text, name.text));
    if (!scope.defs.contains(name.text)) fail(name, fmt::format("USE {} before any DEF {}", name.text, name.text));
  }

  void body(const Token& type, const std::string& def, const Token& brace) {
    const std::string typeName(type.text);
    const auto known = protos_.find(typeName);
    const bool tracked =
        std::find(options_.trackedTypes.begin(), options_.trackedTypes.end(), typeName) != options_.trackedTypes.end();
    int site = -1;
    if (tracked) {
      site = static_cast<int>(result_.sites.size());
      result_.sites.push_back({typeName, def, type.line, type.column, {}});
      if (known != protos_.end() && known->second.fromPrelude)
        insertions_.emplace_back(brace.offset + 1, fmt::format(" drapeNodeId {} ", site));
    }
    while (current_.kind != Tok::CloseBrace) {
      if (current_.kind == Tok::End)
        fail(current_,
             fmt::format("unexpected end of file in {} (the '{{' at line {} is not closed)", typeName, brace.line));
      if (isId("ROUTE")) {
        route();
        continue;
      }
      if (isId("PROTO")) {
        proto();
        continue;
      }
      if (isId("EXTERNPROTO")) {
        externProto();
        continue;
      }
      const Token field = expectName(fmt::format("a field name or '}}' in {}", typeName).c_str());
      if (known != protos_.end()) checkField(known->second.interface, field);
      if (site >= 0) {
        if (field.text == "drapeNodeId") fail(field, "drapeNodeId is set by drape's reader, not by scene files");
        result_.sites[static_cast<std::size_t>(site)].fieldLines[std::string(field.text)] = field.line;
      }
      value(field.text);
    }
    take();
  }

  void checkField(const ProtoInterface& interface, const Token& field) const {
    const auto& f = interface.fields;
    if (std::find(f.begin(), f.end(), field.text) != f.end()) return;
    std::vector<std::string> visible;
    for (const std::string& name : f)
      if (name != "drapeNodeId") visible.push_back(name);
    fail(field, fmt::format("unknown field '{}' in {} (its fields: {})", field.text, interface.name,
                            fmt::join(visible, ", ")));
  }

  // value: [ elements ] | node | IS name | numbers | string | TRUE | FALSE
  void value(std::string_view field) {
    switch (current_.kind) {
      case Tok::OpenBracket: {
        const Token bracket = take();
        open(bracket);
        bool numbers = false;  // a list holds one kind of value: after a number, only numbers
        while (current_.kind != Tok::CloseBracket) {
          if (current_.kind == Tok::End)
            fail(current_, fmt::format("unexpected end of file in the value of {} (the '[' at line {} is not closed)",
                                       field, bracket.line));
          if (numbers && current_.kind != Tok::Number)
            fail(current_, fmt::format("expected a number or ']' in the value of field '{}', found {}", field,
                                       describe(current_)));
          numbers = current_.kind == Tok::Number;
          element(field);
        }
        take();
        close();
        return;
      }
      case Tok::Number:
        while (current_.kind == Tok::Number) take();
        return;
      case Tok::String:
        take();
        return;
      case Tok::Id:
        if (isId("IS")) {
          take();
          expectName("an interface field name after IS");
          return;
        }
        if (isId("TRUE") || isId("FALSE")) {
          take();
          return;
        }
        node();
        return;
      default:
        fail(current_, fmt::format("expected a value for field '{}', found {}", field, describe(current_)));
    }
  }

  void element(std::string_view field) {
    switch (current_.kind) {
      case Tok::Number:
      case Tok::String:
        take();
        return;
      case Tok::Id:
        if (isId("TRUE") || isId("FALSE")) {
          take();
          return;
        }
        node();
        return;
      default:
        fail(current_, fmt::format("unexpected {} in the value of field '{}'", describe(current_), field));
    }
  }

  ScanResult finish() {
    std::string text;
    text.reserve(text_.size() + insertions_.size() * 20);
    std::size_t from = 0;
    for (const auto& [offset, tag] : insertions_) {
      text.append(text_.substr(from, offset - from));
      text += tag;
      from = offset;
    }
    text.append(text_.substr(from));
    result_.text = std::move(text);
    return std::move(result_);
  }

  std::string_view text_;
  const ScanOptions& options_;
  Lexer lexer_;
  Token current_;
  int depth_ = 0;
  std::vector<Scope> scopes_;
  std::map<std::string, Known, std::less<>> protos_;
  std::vector<std::set<std::string, std::less<>>> bodyTypes_;  ///< node types used in each open PROTO
  std::map<std::string, std::set<std::string, std::less<>>, std::less<>>
      protoUses_;  ///< all types a PROTO's instance contains
  std::vector<std::pair<std::size_t, std::string>> insertions_;
  ScanResult result_;
};

}  // namespace

ScanResult scan(std::string_view text, const std::string& file, const ScanOptions& options) {
  if (text.substr(0, kHeader.size()) != kHeader) {
    throw Error::at({file, 1, 1}, fmt::format("not a VRML97 file (it must begin with '{}')", kHeader));
  }
  return Scanner(text, file, options).run();
}

}  // namespace drape::formats::vrml
