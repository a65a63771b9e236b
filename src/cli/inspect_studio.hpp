#pragma once
// `drape inspect nats://HOST:PORT`: what a studio's NATS server holds (docs/STUDIO.md): each
// broadcaster's stream, the take in it, what it carries and how far it has come.

#include <ostream>
#include <string>

namespace drape::cli {

/// Whether `what` names a NATS server rather than a file.
[[nodiscard]] bool isServerUrl(const std::string& what);

/// Prints every drape stream of the server at `url`. Throws drape::Error (Unavailable)
/// when no server answers.
void inspectStudio(const std::string& url, std::ostream& out);

}  // namespace drape::cli
