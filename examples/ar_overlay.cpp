// A crate on a desk, seen by a camera whose pose a tracker knows to 4 mm and 0.5 degrees,
// drawn in 3-D with OpenSceneGraph where the tracking puts it, over a grey video frame,
// with its error regions and label (covtrack::osg). Off screen into a PPM image:
//   ar_overlay OUT.ppm      (needs an X display with OpenGL; headless: xvfb-run -a ar_overlay out.ppm)
// It prints the crate's regions and how many pixels of the image the crate covers.
#include <cstdio>
#include <fstream>
#include <string>
#include <vector>

#include <osg/Geode>
#include <osg/ShapeDrawable>

#include <covtrack/client/ar_view.hpp>
#include <covtrack/client/transform_graph.hpp>
#include <covtrack/osg/ar_scene.hpp>
#include <covtrack/osg/ar_viewer.hpp>
#include <covtrack/protocol/camera.hpp>

using namespace covtrack;

// Binary PPM: any image viewer opens it, and it needs no image library.
bool write_ppm(const cv::Mat& bgr, const std::string& path) {
  std::ofstream out(path, std::ios::binary);
  out << "P6\n" << bgr.cols << " " << bgr.rows << "\n255\n";
  for (int y = 0; y < bgr.rows; ++y)
    for (int x = 0; x < bgr.cols; ++x) {
      const cv::Vec3b p = bgr.at<cv::Vec3b>(y, x);
      out.put(char(p[2])).put(char(p[1])).put(char(p[0]));
    }
  return bool(out);
}

int main(int argc, char** argv) {
  if (argc != 2) return std::fprintf(stderr, "usage: ar_overlay OUT.ppm\n"), 2;
  // world -> camera (tracked, here a fixed estimate) and world -> crate (surveyed).
  client::TransformGraph graph;
  Pose world_camera = Pose::Identity();
  world_camera.translate(Vec3(0, 0, -0.6));
  Vec6 camera_sigmas;
  camera_sigmas << Vec3::Constant(0.004), Vec3::Constant(0.5 * std::numbers::pi / 180);
  (void)graph.add_static_edge("world", "camera", world_camera, camera_sigmas.cwiseAbs2().asDiagonal());
  Pose world_crate = Pose::Identity();
  world_crate.rotate(Eigen::AngleAxisd(0.6, Vec3(1, 1, 0).normalized()));
  (void)graph.add_static_edge("world", "crate", world_crate, Mat6::Identity() * 1e-8);

  const Camera camera{.fx = 525, .fy = 525, .cx = 319.5, .cy = 239.5, .width_px = 640, .height_px = 480};
  const Vec3 half(0.06, 0.04, 0.03);  // a 12 x 8 x 6 cm crate
  client::ArObject crate{.name = "crate", .frame = "crate"};
  for (double x : {-1, 1})
    for (double y : {-1, 1})
      for (double z : {-1, 1}) crate.vertices_object.push_back(half.cwiseProduct(Vec3(x, y, z)));
  auto view = client::ArView::create(camera, "camera", {crate});
  if (!view) return std::fprintf(stderr, "ar_overlay: %s\n", view.error().message.c_str()), 1;
  if (auto r = view->update(graph, 0); !r) return std::fprintf(stderr, "ar_overlay: %s\n", r.error().message.c_str()), 1;

  // The crate's augmentation: a box in its own frame, the same size as its vertices say.
  ar::ArScene scene(camera);
  osg::ref_ptr<osg::Geode> box = new osg::Geode;
  box->addDrawable(new osg::ShapeDrawable(new osg::Box(osg::Vec3(), 2 * half.x(), 2 * half.y(), 2 * half.z())));
  scene.add_object({box});
  scene.set_video(cv::Mat(480, 640, CV_8UC3, cv::Scalar(60, 60, 60)));
  const std::vector<std::string> labels = {"crate"};
  scene.update(view->frame(), labels);

  auto viewer = ar::ArViewer::open(scene, ar::ArViewer::Output::offscreen);
  if (!viewer) return std::fprintf(stderr, "ar_overlay: %s\n", viewer.error().message.c_str()), 1;
  (*viewer)->frame();
  const cv::Mat image = (*viewer)->image();
  int drawn = 0;  // pixels that are not the video's grey
  for (int y = 0; y < image.rows; ++y)
    for (int x = 0; x < image.cols; ++x) drawn += image.at<cv::Vec3b>(y, x) != cv::Vec3b(60, 60, 60);
  const client::ObjectRegions& r = view->frame().objects[0].regions;
  std::printf("crate: outer region %zu corners, inner %zu, %d pixels drawn over the video\n", r.outer.size(),
              r.inner.size(), drawn);
  if (!write_ppm(image, argv[1])) return std::fprintf(stderr, "ar_overlay: cannot write %s\n", argv[1]), 1;
  return 0;
}
