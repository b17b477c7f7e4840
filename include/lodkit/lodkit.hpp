// lodkit's C++ API: include this one header.
//   lod::Service    the LOD thread: models, objects (staged, committed by tick), views, frames
//   lod::Frame      what a frame publishes: per visible object its handle, level, blend, views
//   lod::FrameRef   shared, non-blocking read access to one frame
//   lod::LevelMeshView, lod::Material   a model's level geometry and materials, zero-copy (mesh.hpp)
// The C API over it is lodkit.h.
#pragma once
#include "lodkit/frame.hpp"
#include "lodkit/mesh.hpp"
#include "lodkit/service.hpp"
#include "lodkit/types.hpp"
