// Compiling and linking a GLSL program; the driver's log comes back in the message.
#pragma once
#include <string>

#include <epoxy/gl.h>

namespace lod::viewer {

// Returns the program, or 0 with `message` naming the stage (`what`) and the driver's log.
GLuint build_program(const char* what, const char* vertex_source, const char* fragment_source, std::string* message);

}  // namespace lod::viewer
