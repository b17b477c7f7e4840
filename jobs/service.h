// lod::Service (public API, include/lodkit/service.hpp) and what lodkit's own tools add to it:
// a service over already baked chains and placed objects, with the graph's test hooks.
#pragma once
#include <memory>

#include "jobs/frame_graph.h"
#include "jobs/scene.h"
#include "lodkit/service.hpp"
#include "runtime/view.h"

namespace lod {

// A service over `scene`'s chains (models 0..n-1, in order) with its objects created in
// object order (handles of slots 0..n-1) and committed at tick 0. `graph` gives the threads,
// selection, pixel error, hysteresis, blend time and stage hook.
// `handles`, when given, receives the objects' handles in object order.
std::unique_ptr<Service> make_service(const Scene& scene, const FrameGraphOptions& graph, double rate_hz,
                                      std::vector<ObjectHandle>* handles = nullptr);

// The frame graph options a scene config asks for (threads, budget, pixel error, hysteresis).
FrameGraphOptions frame_graph_options(const SceneConfig& config);

// Adds a baked chain as the next model (the chain must pass validate_chain).
ModelId add_chain(Service& service, LodChain chain);

// One view from the stages' View.
bool set_view(Service& service, uint32_t index, const View& view);

}  // namespace lod
