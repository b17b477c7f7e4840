// Texture URIs live in runtime/ (the service resolves them for renderers without the mesh
// pipeline); the bake's files include them from here.
#pragma once
#include "runtime/texture_uri.h"
