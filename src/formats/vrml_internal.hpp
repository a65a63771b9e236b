#pragma once
// Private to formats/: the pieces of the VRML97 reader shared between the parent side
// (vrml_read.cpp), the Coin side (vrml_coin.cpp, the only file that includes Coin) and the
// wire format (vrml_wire.cpp).

#include <string>
#include <string_view>
#include <vector>

#include "drape/formats/vrml_scan.hpp"
#include "drape/formats/vrml_tree.hpp"

namespace drape::formats::vrml::detail {

/// Scan options with the prelude's PROTOs known and drape's node types tracked.
[[nodiscard]] const ScanOptions& scanOptions();

/// Reads a file's bytes; throws drape::Error naming the path when it cannot.
[[nodiscard]] std::string readBytes(const std::string& path);

/// Resolves a URL of an Inline or EXTERNPROTO (a local file name, "file:" URL, relative
/// to baseDir) to a path, or "" when no such file exists.
[[nodiscard]] std::string resolveUrl(const std::string& url, const std::string& baseDir);

/// Runs Coin on scanned text (in the current process: the caller isolates it).
[[nodiscard]] Document readWithCoin(const ScanResult& scanned, const std::string& file, const std::string& baseDir);

[[nodiscard]] std::string toWire(const Document& document);
/// Throws drape::Error(Internal) when the bytes are not a valid document.
[[nodiscard]] Document fromWire(std::string_view bytes, const std::string& what);

}  // namespace drape::formats::vrml::detail
