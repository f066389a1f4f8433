#include "ar_models.hpp"

#include <array>
#include <filesystem>

#include <fmt/format.h>
#include <osg/BlendFunc>
#include <osg/Geode>
#include <osg/Geometry>
#include <osg/Material>
#include <osgDB/Options>
#include <osgDB/ReadFile>

#include "covtrack/client/object_hull.hpp"

namespace covtrack::cli {
namespace {

osg::Vec4 hull_colour(std::size_t index) {
  static const std::array<osg::Vec4, 6> palette = {{{0.85f, 0.35f, 0.2f, 1}, {0.25f, 0.6f, 0.85f, 1},
                                                     {0.35f, 0.75f, 0.3f, 1}, {0.85f, 0.7f, 0.2f, 1},
                                                     {0.6f, 0.4f, 0.8f, 1}, {0.3f, 0.75f, 0.7f, 1}}};
  return palette[index % palette.size()];
}

// The hull as flat-shaded triangles (each with its own normal, so edges stay crisp).
Result<osg::ref_ptr<osg::Node>> hull_node(const scene::SceneObject& object, std::size_t index) {
  auto triangles = client::convex_hull_triangles_3d(object.vertices_m);
  if (!triangles) return fail(fmt::format("object '{}': {}", object.name, triangles.error().message));
  osg::ref_ptr<osg::Vec3Array> vertices = new osg::Vec3Array, normals = new osg::Vec3Array;
  for (const client::Triangle& t : *triangles) {
    const Vec3 a = object.vertices_m[t[0]], b = object.vertices_m[t[1]], c = object.vertices_m[t[2]];
    const Vec3 n = (b - a).cross(c - a).normalized();
    for (const Vec3& p : {a, b, c}) {
      vertices->push_back(osg::Vec3(float(p.x()), float(p.y()), float(p.z())));
      normals->push_back(osg::Vec3(float(n.x()), float(n.y()), float(n.z())));
    }
  }
  osg::ref_ptr<osg::Geometry> geometry = new osg::Geometry;
  geometry->setVertexArray(vertices);
  geometry->setNormalArray(normals, osg::Array::BIND_PER_VERTEX);
  osg::ref_ptr<osg::Vec4Array> colour = new osg::Vec4Array;
  colour->push_back(hull_colour(index));
  geometry->setColorArray(colour, osg::Array::BIND_OVERALL);
  geometry->addPrimitiveSet(new osg::DrawArrays(GL_TRIANGLES, 0, static_cast<GLsizei>(vertices->size())));
  osg::ref_ptr<osg::Geode> geode = new osg::Geode;
  geode->addDrawable(geometry);
  return osg::ref_ptr<osg::Node>(geode);
}

// The model seen through: blended at 40%, drawn after the opaque ones.
osg::ref_ptr<osg::Node> translucent(osg::Node* model) {
  osg::ref_ptr<osg::Group> group = new osg::Group;
  group->addChild(model);
  osg::StateSet* state = group->getOrCreateStateSet();
  osg::ref_ptr<osg::Material> material = new osg::Material;
  material->setAlpha(osg::Material::FRONT_AND_BACK, 0.4f);
  material->setColorMode(osg::Material::AMBIENT_AND_DIFFUSE);
  state->setAttributeAndModes(material, osg::StateAttribute::ON | osg::StateAttribute::OVERRIDE);
  state->setAttributeAndModes(new osg::BlendFunc(GL_SRC_ALPHA, GL_ONE_MINUS_SRC_ALPHA));
  state->setRenderingHint(osg::StateSet::TRANSPARENT_BIN);
  return group;
}

}  // namespace

Result<std::vector<osg::ref_ptr<osg::Node>>> ar_models(const scene::SceneObject& object, std::size_t index) {
  osg::ref_ptr<osg::Node> model;
  if (!object.model_path.empty()) {
    if (!std::filesystem::is_regular_file(object.model_path))
      return fail(fmt::format("object '{}': model {}: no such file", object.name, object.model_path));
    // The model as its file has it: OSG's OBJ reader would otherwise turn OBJ's y-up
    // convention to z-up (other readers ignore the option).
    osg::ref_ptr<osgDB::Options> options = new osgDB::Options("noRotation");
    model = osgDB::readRefNodeFile(object.model_path, options.get());
    if (!model)
      return fail(fmt::format("object '{}': model {}: OpenSceneGraph cannot read it (is its format's plugin "
                              "installed?)", object.name, object.model_path));
  } else {
    auto hull = hull_node(object, index);
    if (!hull) return std::unexpected(hull.error());
    model = *hull;
  }
  std::vector<osg::ref_ptr<osg::Node>> levels;
  for (scene::Augmentation a : object.augmentations) {
    if (a == scene::Augmentation::outline) levels.push_back(model);
    else if (a == scene::Augmentation::region) levels.push_back(translucent(model.get()));
    else levels.push_back(new osg::Group);  // label: nothing registered
  }
  return levels;
}

}  // namespace covtrack::cli
