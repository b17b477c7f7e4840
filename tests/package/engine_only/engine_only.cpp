// lod::Service over a baked .lod asset, linked against lodkit::engine alone (no mesh pipeline).
// usage: engine_only FILE.lod
#include <lodkit/lodkit.hpp>

#include <cstdio>
#include <optional>

int main(int argc, char** argv) {
  if (argc != 2) return std::fprintf(stderr, "usage: %s FILE.lod\n", argv[0]), 2;
  lod::Service service;
  lod::ModelId model = 0;
  if (!service.add_model(argv[1], &model)) return std::fprintf(stderr, "%s\n", service.last_error().c_str()), 1;
  // Level geometry for a renderer comes from the engine alone too.
  const std::optional<lod::LevelMeshView> mesh = service.level_mesh(model, 0);
  if (!mesh || mesh->triangle_count() != service.level_triangles(model, 0) || mesh->positions.empty())
    return std::fprintf(stderr, "level_mesh: %s\n", service.last_error().c_str()), 1;
  for (int i = 0; i < 16; ++i) {
    lod::Transform t;
    t.position[0] = 3.0f * float(i);
    if (service.create(model, t) == 0) return std::fprintf(stderr, "create: %s\n", service.last_error().c_str()), 1;
  }
  service.commit(1);
  lod::Camera camera;
  camera.eye[0] = 24, camera.eye[1] = 2, camera.eye[2] = 40;
  if (!service.set_view(0, camera)) return std::fprintf(stderr, "set_view: %s\n", service.last_error().c_str()), 1;
  if (!service.step(1.0 / 60)) return std::fprintf(stderr, "step: %s\n", service.last_error().c_str()), 1;
  const lod::FrameRef frame = service.acquire_frame();
  if (!frame) return std::fprintf(stderr, "no frame after step\n"), 1;
  std::printf("engine only: tick %llu, %u objects, %u visible, %llu triangles\n", (unsigned long long)frame->tick,
              frame->object_count, frame->visible, (unsigned long long)frame->tris_selected);
  return frame->tick == 1 && frame->object_count == 16 && frame->visible > 0 ? 0 : 1;
}
