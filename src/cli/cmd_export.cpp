// `drape export OUTDIR --glb out.glb`: a finished run as animated glTF 2.0 (binary).

#include <filesystem>
#include <iostream>

#include <fmt/format.h>

#include "command.hpp"
#include "drape/formats/gltf_writer.hpp"

namespace drape::cli {
namespace {

struct ExportOptions {
  std::string run;
  std::string glb;
  std::string body = "segments";  ///< --body
};

RunFunction setupExport(CLI::App& app) {
  static ExportOptions o;
  app.add_option("run", o.run, "A run directory (with manifest.json), as drape run --out writes")->required();
  app.add_option("--glb", o.glb, "The binary glTF file to write (default: RUN/result.glb)");
  app.add_option("--body", o.body,
                 "segments: each character as the rigid parts the cloth collides with (small); skin: as its skinned "
                 "body and drawn meshes, as the players draw it (a morph target per frame)")
      ->check(CLI::IsMember({"segments", "skin"}))
      ->capture_default_str();
  app.footer(
      "Garments become meshes with one morph target per frame and a weights animation; body parts\n"
      "that move rigidly become nodes with translation and rotation animation; with --body skin, a\n"
      "character's skinned body and drawn meshes are morph-target meshes instead of its parts.");
  return [] {
    const std::string glb = o.glb.empty() ? (std::filesystem::path(o.run) / "result.glb").string() : o.glb;
    const bool skin = o.body == "skin";
    const formats::RunExportSummary s =
        formats::exportRunToGlb(o.run, glb, skin ? formats::ExportedBody::Skin : formats::ExportedBody::Segments);
    std::cout << fmt::format("wrote {} ({} frames; {} morph-target meshes, {} rigid nodes)\n", glb, s.frames,
                             s.deforming, s.rigid);
    if (skin && s.skins == 0)
      std::cout << "the run has no skinned body (its avatar is rigid parts only): its parts were written\n";
    return 0;
  };
}

const bool registered_cmd_export = registerCommand({"export", "Export a run as animated glTF 2.0 (.glb)", "", 42, &setupExport});

}  // namespace
}  // namespace drape::cli
