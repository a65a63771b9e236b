#pragma once
// Small OpenGL helpers shared by the renderer, the headless context and the player.
// Internal to render/: epoxy is the one GL loader (it serves GLX windows and EGL alike).

#include <epoxy/gl.h>

#include <string>

namespace drape::render::gl {

/// Compiles and links a vertex + fragment program; throws drape::Error (internal) with the
/// driver's log and `what` on failure.
GLuint buildProgram(const char* vertexSource, const char* fragmentSource, const std::string& what);

/// "OpenGL <version> (<renderer>)" of the current context.
std::string describeContext();

/// Throws drape::Error (internal) when the current context is older than OpenGL 3.3.
void requireGl33(const std::string& where);

}  // namespace drape::render::gl
