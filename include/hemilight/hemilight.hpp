// hemilight/hemilight.hpp — the umbrella header: includes every module of the C++ API.
//
// Modules, left to right along the pipeline (a module includes only modules to its left):
//   error.hpp     status codes, hemilight::error, version
//   geometry.hpp  hemicube layout and exact texel weights, GL cube-map faces, frames
//   image_io.hpp  float images and cube maps as OpenEXR
#pragma once

#include "hemilight/error.hpp"
#include "hemilight/geometry.hpp"
#include "hemilight/image_io.hpp"
