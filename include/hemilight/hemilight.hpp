// hemilight/hemilight.hpp — the umbrella header: includes every module of the C++ API.
//
// Modules by stage, in pipeline order (docs/design.md, "Layers"; a stage includes only the
// stages below it):
//   core       error.hpp (status codes, hemilight::error, version), parallel.hpp (parallel_for),
//              geometry.hpp (hemicube layout, exact texel weights, frames, cube faces),
//              image_io.hpp (float images and cube maps as OpenEXR), memory.hpp (the table budget)
//   scene      scene.hpp: immutable triangle scenes with materials, lightmap UVs, sky and BVH
//   unwrap     unwrap.hpp: lightmap UVs for any mesh: charts, conformal maps, packing into pages
//   cubemap    cubemap.hpp: environment cube maps: mappings, sampling, lookup fixup, filtering, SH
//   rays       rays.hpp (shadow and closest-hit rays), lights.hpp (sun, point, spot, rect lights)
//   raster     hemicube.hpp (the hemicube buffer), raster.hpp (the software hemicube rasterizer)
//   integrate  integrate.hpp: irradiance, gradients and split-sphere distances from a buffer
//   sampler    sampler.hpp: irradiance at a point from one hemicube, directional projections
//   cache      cache.hpp: the irradiance cache: records, radii, deterministic placement
//   probes     probes.hpp: light probes: SH9 of the radiance at points
//   bake       bake.hpp: the lightmap baker: UV coverage, samples, bounces, dilation;
//              seams.hpp: the seams of a lightmap and their measured step (the baker stitches them);
//              shards.hpp: a scene bake split into jobs for other processes or machines
// The reference scenes by name are fixtures, outside the library (fixtures/, reference_scenes.hpp).
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
#include "hemilight/sampler.hpp"
#include "hemilight/scene.hpp"
#include "hemilight/seams.hpp"
#include "hemilight/shards.hpp"
#include "hemilight/unwrap.hpp"
