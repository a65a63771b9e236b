#pragma once
// Building a Scene from a VRML97 document already read (for callers that read VRML97 text
// from elsewhere, e.g. a scene sent over the network, and for tests).

#include "drape/formats/vrml_tree.hpp"
#include "drape/scene/scene.hpp"

namespace drape::scene {

/// Builds the scene of `document` (see loadScene for the errors it throws).
[[nodiscard]] Scene buildScene(const formats::vrml::Document& document);

}  // namespace drape::scene
