// The parent's program: a service from a scene config through lodkit::lodkit, a few objects,
// one driven frame. usage: parent_app SCENE.toml
#include <lodkit/lodkit.hpp>

#include <cstdio>
#include <string>

static_assert(__cplusplus >= 202002L, "lodkit::lodkit must bring C++20 with it");

int main(int argc, char** argv) {
  if (argc != 2) return std::fprintf(stderr, "usage: %s SCENE.toml\n", argv[0]), 2;
  std::string error;
  const auto service = lod::Service::from_config(argv[1], &error);
  if (!service) return std::fprintf(stderr, "%s\n", error.c_str()), 1;
  if (service->model_count() == 0) return std::fprintf(stderr, "%s has no [[model]]\n", argv[1]), 1;
  const uint64_t before = service->stats().live_objects;
  for (int i = 0; i < 8; ++i) {
    lod::Transform t;
    t.position[0] = 3.0f * float(i);
    if (service->create(0, t) == 0) return std::fprintf(stderr, "create: %s\n", service->last_error().c_str()), 1;
  }
  service->commit(7);
  lod::Camera camera;
  camera.eye[0] = 12, camera.eye[1] = 2, camera.eye[2] = 30;
  if (!service->set_view(0, camera) || !service->step(1.0 / 60))
    return std::fprintf(stderr, "%s\n", service->last_error().c_str()), 1;
  const lod::FrameRef frame = service->acquire_frame();
  if (!frame || frame->tick != 7 || frame->object_count != before + 8)
    return std::fprintf(stderr, "frame: missing, or not of tick 7 with %llu objects\n",
                        (unsigned long long)(before + 8)), 1;
  std::printf("parent: %u visible, %llu triangles\n", frame->visible, (unsigned long long)frame->tris_selected);
  return 0;
}
