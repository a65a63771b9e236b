#include "parse_errors.hpp"

#include <algorithm>
#include <cctype>
#include <optional>
#include <string_view>
#include <vector>

#include <fmt/format.h>

namespace drape::cli {
namespace {

/// Edits (insertions, deletions, substitutions, swaps of neighbours) between two words.
std::size_t editDistance(std::string_view a, std::string_view b) {
  // Optimal string alignment: Levenshtein's three edits and a swap of two neighbours (the
  // commonest slip of a typing hand), over three rows of the table.
  std::vector<std::size_t> before(b.size() + 1), last(b.size() + 1), row(b.size() + 1);
  for (std::size_t j = 0; j <= b.size(); ++j) last[j] = j;
  for (std::size_t i = 1; i <= a.size(); ++i) {
    row[0] = i;
    for (std::size_t j = 1; j <= b.size(); ++j) {
      const std::size_t substitution = last[j - 1] + (a[i - 1] == b[j - 1] ? 0 : 1);
      row[j] = std::min({last[j] + 1, row[j - 1] + 1, substitution});
      if (i > 1 && j > 1 && a[i - 1] == b[j - 2] && a[i - 2] == b[j - 1]) row[j] = std::min(row[j], before[j - 2] + 1);
    }
    before.swap(last);
    last.swap(row);
  }
  return last[b.size()];
}

/// Of `names` (distinct), the one nearest `word` if it is near enough to be what was meant (at
/// most one edit in a word of up to five letters, two in a longer one) and nearer than any other.
std::optional<std::string> nearestName(std::string_view word, const std::vector<std::string>& names) {
  std::string_view letters = word;
  while (!letters.empty() && letters.front() == '-') letters.remove_prefix(1);
  const std::size_t allowed = letters.size() <= 5 ? 1 : 2;
  std::optional<std::string> nearest;
  std::size_t best = allowed + 1;
  bool tied = false;
  for (const std::string& name : names) {
    if (name == word) continue;
    const std::size_t d = editDistance(word, name);
    if (d < best) {
      best = d;
      nearest = name;
      tied = false;
    } else if (d == best) {  // the names are distinct: another as near
      tied = true;
    }
  }
  if (tied) return std::nullopt;
  return nearest;
}

/// The long and short names (with their dashes) of the options `app` takes, the ones of the
/// commands it falls through to included, and the names of its subcommands.
std::vector<std::string> namesTakenBy(const CLI::App& app) {
  std::vector<std::string> names;
  for (const CLI::App* a = &app; a != nullptr; a = a->get_parent()) {
    for (const CLI::Option* option : a->get_options()) {
      for (const std::string& n : option->get_lnames()) names.push_back("--" + n);
      for (const std::string& n : option->get_snames()) names.push_back("-" + n);
    }
    if (!a->get_fallthrough()) break;
  }
  for (const CLI::App* sub : app.get_subcommands([](const CLI::App*) { return true; }))
    names.push_back(sub->get_name());
  std::sort(names.begin(), names.end());
  names.erase(std::unique(names.begin(), names.end()), names.end());
  return names;
}

/// The command line's deepest command CLI11 had reached ("drape bench paper").
const CLI::App& deepestCommand(const CLI::App& root) {
  const CLI::App* app = &root;
  for (;;) {
    const std::vector<CLI::App*> parsed = app->get_subcommands();
    if (parsed.empty()) return *app;
    app = parsed.front();
  }
}

/// Words other tools, or drape's other commands, use for what a command names otherwise
/// (`drape export RUN --out x.glb` means --glb), each with the names it may mean, offered in
/// this order where the command takes them. Spelling alone finds none of these.
struct Meaning {
  std::vector<std::string_view> words;
  std::vector<std::string_view> names;
};
const std::vector<Meaning>& meanings() {
  static const std::vector<Meaning> table = {
      {{"--out", "-o", "--output"}, {"--out", "--glb", "--png", "--video", "--contact-sheet", "--record", "--screenshot"}},
      {{"--nats", "--url", "--bus", "--nats-server"}, {"--server"}},
      {{"--steps", "--steps-per-frame"}, {"--substeps"}},
  };
  return table;
}

/// The names `word` may mean (meanings()) among those `taken`, in the table's order.
std::vector<std::string> meantBy(std::string_view word, const std::vector<std::string>& taken) {
  std::vector<std::string> meant;
  for (const Meaning& m : meanings()) {
    if (std::find(m.words.begin(), m.words.end(), word) == m.words.end()) continue;
    for (const std::string_view name : m.names)
      if (name != word && std::binary_search(taken.begin(), taken.end(), std::string(name)))
        meant.emplace_back(name);
  }
  return meant;
}

/// "A", "A or B", "A, B or C".
std::string oneOf(const std::vector<std::string>& names) {
  std::string text;
  for (std::size_t i = 0; i < names.size(); ++i)
    text += (i == 0 ? "" : i + 1 == names.size() ? " or " : ", ") + names[i];
  return text;
}

/// "drape bench paper": the program and the commands down to `app`.
std::string commandLineOf(const CLI::App& app) {
  std::vector<std::string> names;
  for (const CLI::App* a = &app; a->get_parent() != nullptr; a = a->get_parent()) names.push_back(a->get_name());
  std::string line = "drape";
  for (auto it = names.rbegin(); it != names.rend(); ++it) line += " " + *it;
  return line;
}

}  // namespace

std::string parseErrorMessage(const CLI::App& root, const CLI::ParseError& e) {
  const CLI::App& command = deepestCommand(root);
  const std::string name = commandLineOf(command);
  std::string said = e.what();
  if (said.size() > 1 && std::isupper(static_cast<unsigned char>(said[0])) &&
      !std::isupper(static_cast<unsigned char>(said[1])))  // "The following ...", "A subcommand ...", not "VRML"
    said[0] = static_cast<char>(std::tolower(static_cast<unsigned char>(said[0])));
  std::string message = fmt::format("{}: {}", name, said);
  const std::vector<std::string> taken = namesTakenBy(command);
  // The words CLI11 left over: a mistyped option or command among them (also where the
  // error itself is another, such as a required option missing).
  for (const std::string& word : root.remaining(true)) {
    const std::optional<std::string> nearest = nearestName(word, taken);
    const std::vector<std::string> meant = nearest ? std::vector<std::string>{*nearest} : meantBy(word, taken);
    if (!meant.empty()) message += fmt::format("\n  {}: did you mean {}?", word, oneOf(meant));
  }
  message += fmt::format("\n'{} --help' lists {}", name,
                         command.get_subcommands([](const CLI::App*) { return true; }).empty()
                             ? "its options"
                             : "its options and commands");
  return message;
}

}  // namespace drape::cli
