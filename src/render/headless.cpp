#include "drape/render/headless.hpp"

#include <epoxy/egl.h>
#include <epoxy/gl.h>

#include <cstring>

#include <fmt/format.h>

#include "drape/core/error.hpp"
#include "gl_util.hpp"
#include "hud.hpp"

namespace drape::render {
namespace {

constexpr int kSamples = 4;  // multisampling: smooth silhouettes and grid lines

/// An OpenGL 3.3 core context on Mesa's surfaceless EGL platform: no window system, no
/// GPU needed (llvmpipe). The display is shared by the process and never terminated, so
/// several renderers may live side by side.
struct EglContext {
  EGLDisplay display = EGL_NO_DISPLAY;
  EGLContext context = EGL_NO_CONTEXT;

  EglContext() {
    // libepoxy aborts on the first EGL call when libEGL cannot be loaded: ask first.
    if (!epoxy_has_egl()) {
      throw Error("headless rendering: libEGL is not available (install libegl1 and libegl-mesa0)", ExitCode::Internal);
    }
    const char* clientExtensions = eglQueryString(EGL_NO_DISPLAY, EGL_EXTENSIONS);
    if (clientExtensions == nullptr || std::strstr(clientExtensions, "EGL_MESA_platform_surfaceless") == nullptr) {
      throw Error("headless rendering: EGL has no surfaceless platform (install libegl1 and libegl-mesa0)",
                  ExitCode::Internal);
    }
    display = eglGetPlatformDisplayEXT(EGL_PLATFORM_SURFACELESS_MESA, EGL_DEFAULT_DISPLAY, nullptr);
    EGLint major = 0, minor = 0;
    if (display == EGL_NO_DISPLAY || eglInitialize(display, &major, &minor) != EGL_TRUE) {
      throw Error("headless rendering: cannot open the EGL surfaceless display (install libgl1-mesa-dri)",
                  ExitCode::Internal);
    }
    if (eglBindAPI(EGL_OPENGL_API) != EGL_TRUE)
      throw Error("headless rendering: EGL cannot bind OpenGL", ExitCode::Internal);
    const EGLint attributes[] = {
        EGL_CONTEXT_MAJOR_VERSION,           3,       EGL_CONTEXT_MINOR_VERSION, 3, EGL_CONTEXT_OPENGL_PROFILE_MASK,
        EGL_CONTEXT_OPENGL_CORE_PROFILE_BIT, EGL_NONE};
    context = eglCreateContext(display, EGL_NO_CONFIG_KHR, EGL_NO_CONTEXT, attributes);
    if (context == EGL_NO_CONTEXT) {
      throw Error(fmt::format("headless rendering: no OpenGL 3.3 core context (EGL error 0x{:x})", eglGetError()),
                  ExitCode::Internal);
    }
    makeCurrent();
  }
  ~EglContext() {
    if (context != EGL_NO_CONTEXT) {
      eglMakeCurrent(display, EGL_NO_SURFACE, EGL_NO_SURFACE, EGL_NO_CONTEXT);
      eglDestroyContext(display, context);
    }
  }
  EglContext(const EglContext&) = delete;
  EglContext& operator=(const EglContext&) = delete;

  void makeCurrent() const {
    if (eglMakeCurrent(display, EGL_NO_SURFACE, EGL_NO_SURFACE, context) != EGL_TRUE) {
      throw Error("headless rendering: cannot make the EGL context current", ExitCode::Internal);
    }
  }
};

/// A multisampled framebuffer (colour, depth + stencil) resolved into a plain one for reading.
struct Framebuffers {
  GLuint msFbo = 0, msColour = 0, msDepth = 0, fbo = 0, colour = 0;
  int width = 0, height = 0;

  void create(int w, int h) {
    width = w;
    height = h;
    glGenFramebuffers(1, &msFbo);
    glBindFramebuffer(GL_FRAMEBUFFER, msFbo);
    glGenRenderbuffers(1, &msColour);
    glBindRenderbuffer(GL_RENDERBUFFER, msColour);
    glRenderbufferStorageMultisample(GL_RENDERBUFFER, kSamples, GL_RGBA8, w, h);
    glFramebufferRenderbuffer(GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT0, GL_RENDERBUFFER, msColour);
    glGenRenderbuffers(1, &msDepth);
    glBindRenderbuffer(GL_RENDERBUFFER, msDepth);
    glRenderbufferStorageMultisample(GL_RENDERBUFFER, kSamples, GL_DEPTH24_STENCIL8, w, h);
    glFramebufferRenderbuffer(GL_FRAMEBUFFER, GL_DEPTH_STENCIL_ATTACHMENT, GL_RENDERBUFFER, msDepth);
    check("multisampled");
    glGenFramebuffers(1, &fbo);
    glBindFramebuffer(GL_FRAMEBUFFER, fbo);
    glGenRenderbuffers(1, &colour);
    glBindRenderbuffer(GL_RENDERBUFFER, colour);
    glRenderbufferStorage(GL_RENDERBUFFER, GL_RGBA8, w, h);
    glFramebufferRenderbuffer(GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT0, GL_RENDERBUFFER, colour);
    check("resolve");
  }
  void destroy() {
    glDeleteFramebuffers(1, &msFbo);
    glDeleteFramebuffers(1, &fbo);
    const GLuint buffers[] = {msColour, msDepth, colour};
    glDeleteRenderbuffers(3, buffers);
    msFbo = msColour = msDepth = fbo = colour = 0;
  }
  static void check(const char* which) {
    if (glCheckFramebufferStatus(GL_FRAMEBUFFER) != GL_FRAMEBUFFER_COMPLETE) {
      throw Error(fmt::format("headless rendering: the {} framebuffer is incomplete", which), ExitCode::Internal);
    }
  }
};

}  // namespace

struct HeadlessRenderer::Impl {
  EglContext egl;
  Framebuffers fb;
  std::unique_ptr<Renderer> renderer;
  std::unique_ptr<ImGuiLayer> imgui;
};

HeadlessRenderer::HeadlessRenderer(std::vector<MeshInfo> meshes, int width, int height)
    : impl_(std::make_unique<Impl>()) {
  if (width < 16 || height < 16 || width > 8192 || height > 8192) {
    throw Error(fmt::format("image size {}x{} is outside 16x16 .. 8192x8192", width, height));
  }
  gl::requireGl33("headless rendering");
  impl_->fb.create(width, height);
  impl_->renderer = std::make_unique<Renderer>(std::move(meshes));
  impl_->imgui = std::make_unique<ImGuiLayer>();
}

HeadlessRenderer::~HeadlessRenderer() {
  impl_->egl.makeCurrent();
  impl_->imgui.reset();
  impl_->renderer.reset();
  impl_->fb.destroy();
}

Renderer& HeadlessRenderer::renderer() { return *impl_->renderer; }

std::string HeadlessRenderer::description() const {
  impl_->egl.makeCurrent();
  return gl::describeContext();
}

void HeadlessRenderer::resize(int width, int height) {
  if (width == impl_->fb.width && height == impl_->fb.height) return;
  impl_->egl.makeCurrent();
  impl_->fb.destroy();
  impl_->fb.create(width, height);
}

Image HeadlessRenderer::render(const Frame& frame, const ViewSettings& view, const OverlaySettings& overlay) {
  HudInfo none;
  none.show = false;
  return render(frame, view, overlay, none);
}

Image HeadlessRenderer::render(const Frame& frame, const ViewSettings& view, const OverlaySettings& overlay,
                               const HudInfo& hud) {
  Impl& s = *impl_;
  s.egl.makeCurrent();
  const int w = s.fb.width, h = s.fb.height;
  glBindFramebuffer(GL_FRAMEBUFFER, s.fb.msFbo);
  s.renderer->setFrame(frame);
  s.renderer->draw(w, h, view, overlay);
  if (hud.show) {
    s.imgui->beginFrame(w, h);
    s.imgui->drawHud(hud, w, h);
    s.imgui->endFrame();
  }
  // Resolve the samples, then read back bottom-up rows and flip them.
  glBindFramebuffer(GL_READ_FRAMEBUFFER, s.fb.msFbo);
  glBindFramebuffer(GL_DRAW_FRAMEBUFFER, s.fb.fbo);
  glBlitFramebuffer(0, 0, w, h, 0, 0, w, h, GL_COLOR_BUFFER_BIT, GL_NEAREST);
  glBindFramebuffer(GL_READ_FRAMEBUFFER, s.fb.fbo);
  glPixelStorei(GL_PACK_ALIGNMENT, 1);
  std::vector<std::uint8_t> rows(static_cast<std::size_t>(w) * static_cast<std::size_t>(h) * 3);
  glReadPixels(0, 0, w, h, GL_RGB, GL_UNSIGNED_BYTE, rows.data());
  glBindFramebuffer(GL_FRAMEBUFFER, 0);
  Image image;
  image.width = w;
  image.height = h;
  image.rgb.resize(rows.size());
  const std::size_t stride = static_cast<std::size_t>(w) * 3;
  for (int y = 0; y < h; ++y) {
    std::memcpy(image.rgb.data() + static_cast<std::size_t>(y) * stride,
                rows.data() + static_cast<std::size_t>(h - 1 - y) * stride, stride);
  }
  return image;
}

}  // namespace drape::render
