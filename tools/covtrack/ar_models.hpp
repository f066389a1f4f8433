#pragma once
// What `covtrack ar` draws for each object at each Level-of-Error level, in its frame:
//   outline: its 3-D model (the scene's `model` file, any format OpenSceneGraph reads), or
//            failing one its convex hull, shaded;
//   region:  the same, translucent, so the region drawn around it shows through;
//   label:   nothing registered (the label, listed in the corner, is the cue).
#include <string>
#include <vector>

#include <osg/Node>

#include "covtrack/protocol/result.hpp"
#include "covtrack/scene/scene.hpp"

namespace covtrack::cli {

// One node per level of `object`; `index` picks its hull's colour. Fails naming a model
// file that cannot be read.
Result<std::vector<osg::ref_ptr<osg::Node>>> ar_models(const scene::SceneObject& object, std::size_t index);

}  // namespace covtrack::cli
