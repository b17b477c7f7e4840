// The Frame a pass of the per-frame graph publishes lives in the public API.
#pragma once
#include "lodkit/frame.hpp"
