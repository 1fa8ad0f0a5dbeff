// hemilight/hemilight.hpp — the umbrella header: includes every module of the C++ API.
//
// Modules, left to right along the pipeline (a module includes only modules to its left):
//   error.hpp     status codes, hemilight::error, version
//   geometry.hpp  hemicube layout and exact texel weights, GL cube-map faces, frames
//   image_io.hpp  float images and cube maps as OpenEXR
//   memory.hpp    the budget of the tables kept between calls, and freeing them
//   parallel.hpp  parallel_for: the one way hemilight uses several cores
//   hemicube.hpp  the hemicube buffer: radiance, distance and flags per texel
//   scene.hpp     immutable triangle scenes with materials, lightmap UVs, sky and BVH
//   raster.hpp    the software hemicube rasterizer
//   integrate.hpp irradiance, gradients and split-sphere distances from a hemicube buffer
//   rays.hpp      shadow and closest-hit ray queries against a scene
//   lights.hpp    sun, point, spot and rect lights: direct irradiance with shadow rays
//   cache.hpp     the irradiance cache: records, radii, deterministic placement, interpolation
//   bake.hpp      the lightmap baker: UV coverage, samples, bounces, dilation
//   cubemap.hpp   environment cube maps: mappings, sampling, lookup fixup, filtering, SH
//   probes.hpp    light probes: SH9 of the radiance at points (two hemicubes and the lights)
#pragma once

#include "hemilight/bake.hpp"
#include "hemilight/cache.hpp"
#include "hemilight/cubemap.hpp"
#include "hemilight/error.hpp"
#include "hemilight/geometry.hpp"
#include "hemilight/hemicube.hpp"
#include "hemilight/image_io.hpp"
#include "hemilight/integrate.hpp"
#include "hemilight/lights.hpp"
#include "hemilight/memory.hpp"
#include "hemilight/parallel.hpp"
#include "hemilight/probes.hpp"
#include "hemilight/raster.hpp"
#include "hemilight/rays.hpp"
#include "hemilight/scene.hpp"
