// `drape inspect FILE`: a readable summary of any file drape reads. The readers register
// an inspector per file extension (registerInspector in their cmd_inspect_*.cpp).

#include <algorithm>
#include <filesystem>
#include <iostream>

#include <fmt/format.h>

#include "command.hpp"
#include "drape/core/error.hpp"

namespace drape::cli {
namespace {

std::vector<InspectorEntry>& inspectors() {
  static std::vector<InspectorEntry> entries;
  return entries;
}

std::string lowerExtension(const std::string& path) {
  std::string ext = std::filesystem::path(path).extension().string();
  std::transform(ext.begin(), ext.end(), ext.begin(), [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  return ext;
}

RunFunction setupInspect(CLI::App& app) {
  static std::string path;
  app.add_option("file", path, "The file to summarise")->required();
  app.footer([] {
    std::string text = "Understands:";
    for (const InspectorEntry& e : registeredInspectors()) text += fmt::format("\n  {:<18} {}", fmt::join(e.extensions, " "), e.what);
    return text;
  });
  return [] {
    if (!std::filesystem::exists(path)) throw Error(fmt::format("{}: no such file", path));
    const std::string ext = lowerExtension(path);
    for (const InspectorEntry& e : registeredInspectors()) {
      if (std::find(e.extensions.begin(), e.extensions.end(), ext) != e.extensions.end()) {
        e.inspect(path, std::cout);
        return 0;
      }
    }
    throw Error(fmt::format("{}: drape cannot inspect '{}' files (see drape inspect --help)", path, ext));
  };
}

const bool registered = registerCommand({"inspect", "Print a readable summary of a scene, avatar, motion or mesh file", "", 30, &setupInspect});

}  // namespace

bool registerInspector(std::vector<std::string> extensions, std::string what, Inspector inspector) {
  inspectors().push_back({std::move(extensions), std::move(what), std::move(inspector)});
  return true;
}

const std::vector<InspectorEntry>& registeredInspectors() { return inspectors(); }

}  // namespace drape::cli
