/* hemilight.h — the C ABI of hemilight (C99, no C++ inside).
 *
 * hemilight bakes diffuse global illumination on the CPU: a software hemicube rasterizer, exact
 * hemicube integration with irradiance gradients, an irradiance cache, and seamless cube-map
 * filtering. This header is the stable interface for engines; link with -lhemilight_c
 * (CMake: hemilight::capi, pkg-config: hemilight).
 *
 * Conventions
 *   - Every function returns hemilight_status. On failure nothing is written to the caller's
 *     outputs and hemilight_last_error() describes the problem, naming the bad argument.
 *   - No C++ exception ever leaves this library.
 *   - Directions and positions are float[3] (x, y, z); frames are right-handed.
 *   - Radiance is in W m^-2 sr^-1 (or any consistent unit); irradiance is the integral of
 *     L cos(theta) d omega, so a uniform sky of radiance L gives pi L. No hidden 1/pi.
 *   - Images are float, channels interleaved, rows one after another, row 0 first; cube maps are
 *     six faces in OpenGL order (+X, -X, +Y, -Y, +Z, -Z), face-major, each size x size texels with
 *     x along the GL s coordinate and y along t.
 *   - Thread safety: every function may be called from any thread; objects are immutable after
 *     creation unless a function says otherwise.
 */
#ifndef HEMILIGHT_H
#define HEMILIGHT_H

#include <stddef.h>
#include <stdint.h>

#if defined(_WIN32)
#  if defined(HEMILIGHT_BUILDING_CAPI)
#    define HEMILIGHT_API __declspec(dllexport)
#  else
#    define HEMILIGHT_API __declspec(dllimport)
#  endif
#elif defined(__GNUC__) || defined(__clang__)
#  define HEMILIGHT_API __attribute__((visibility("default")))
#else
#  define HEMILIGHT_API
#endif

#ifdef __cplusplus
extern "C" {
#endif

/* Compile-time version of this header; hemilight_version() gives the library's. */
#define HEMILIGHT_VERSION_MAJOR 0
#define HEMILIGHT_VERSION_MINOR 1
#define HEMILIGHT_VERSION_PATCH 0

typedef enum hemilight_status {
  HEMILIGHT_OK = 0,
  HEMILIGHT_ERROR_INVALID_ARGUMENT, /* NULL, NaN/Inf, out-of-range or inconsistent argument */
  HEMILIGHT_ERROR_OUT_OF_MEMORY,    /* allocation failed, or a size over a documented limit */
  HEMILIGHT_ERROR_IO,               /* file missing, unreadable, truncated, corrupt, or not written */
  HEMILIGHT_ERROR_UNSUPPORTED,      /* valid but not handled: e.g. an EXR without R, G, B */
  HEMILIGHT_ERROR_CANCELLED,        /* a progress callback asked to stop */
  HEMILIGHT_ERROR_INTERNAL          /* a bug in hemilight: please report it */
} hemilight_status;

/* The message of the last failure on the calling thread ("" if none yet). Never NULL. The
 * pointer stays valid until the next hemilight call on the same thread. */
HEMILIGHT_API const char* hemilight_last_error(void);

/* The library's version. Any pointer may be NULL. */
HEMILIGHT_API void hemilight_version(int* major, int* minor, int* patch);

/* ---- hemicube geometry ------------------------------------------------------------------------
 * A hemicube of resolution N (even, 2..4096) has a top face of N x N texels and four side faces
 * (+x, -x, +y, -y) of N x N/2 texels: 3 N^2 texels, numbered top face first, then the side faces in
 * that order, row-major inside each face. In the local frame the surface normal is +z; the top
 * face's texel (0, 0) is at the corner (-1, -1) and its rows go towards +y; a side face's rows
 * start at the horizon and go up, and its columns run along z x (face axis). See
 * include/hemilight/geometry.hpp for the full table. */

/* Number of texels of a hemicube of resolution N: 3 N^2.
 * Errors: INVALID_ARGUMENT if count is NULL or N is odd or outside [2, 4096]. */
HEMILIGHT_API hemilight_status hemilight_hemicube_texel_count(int resolution, size_t* count);

/* One texel's unit centre direction (local frame, z >= 0), exact solid angle (sr) and exact
 * projected solid angle (integral of cos(theta) over the texel, sr). Solid angles sum to 2 pi,
 * projected solid angles to pi. Any output pointer may be NULL (not written).
 * Errors: INVALID_ARGUMENT for an invalid N or texel >= 3 N^2. Cost: O(1) (a cached table). */
HEMILIGHT_API hemilight_status hemilight_hemicube_texel_info(int resolution, size_t texel, float direction[3],
                                                             float* solid_angle, float* projected_solid_angle);

/* ---- OpenEXR images ----------------------------------------------------------------------------
 * Two calls to read: hemilight_exr_info for the size, then a load into a buffer the caller owns.
 * Readers accept any scanline or tiled EXR with channels R, G, B (A and others are ignored), of
 * half, float or uint type. Images of more than 2^28 pixels are refused (OUT_OF_MEMORY). */

/* Width and height of an EXR image, and whether it is a cube map (envmap attribute = cube, or
 * height == 6 x width). Any output may be NULL. Errors: INVALID_ARGUMENT (path NULL), IO (missing,
 * unreadable or corrupt file), UNSUPPORTED (no R, G, B channels). */
HEMILIGHT_API hemilight_status hemilight_exr_info(const char* path, int* width, int* height, int* is_cubemap);

/* Reads an EXR image as float RGB into rgb (capacity in floats, at least width x height x 3).
 * width and height (may be NULL) receive the size. Errors: as hemilight_exr_info, and
 * INVALID_ARGUMENT when rgb is NULL or capacity is too small (nothing is written then). */
HEMILIGHT_API hemilight_status hemilight_exr_load_rgb(const char* path, float* rgb, size_t capacity, int* width,
                                                      int* height);

/* Writes float RGB pixels (width x height x 3 floats) as an EXR file, 32-bit float channels or,
 * when half_float is nonzero, 16-bit half. The file is replaced atomically: on failure any
 * existing file is left as it was. Errors: INVALID_ARGUMENT (NULL, sizes <= 0 or over the limit,
 * non-finite values are allowed), IO (cannot write). */
HEMILIGHT_API hemilight_status hemilight_exr_save_rgb(const char* path, const float* rgb, int width, int height,
                                                      int half_float);

/* Reads an ENVMAP_CUBE EXR (size x 6 size) as six GL-ordered faces of float RGB into faces
 * (capacity in floats, at least 6 x size x size x 3); size receives the face size (may be NULL).
 * Errors: as hemilight_exr_load_rgb, and UNSUPPORTED when the image is not 6x as tall as wide or
 * is a latlong map. */
HEMILIGHT_API hemilight_status hemilight_exr_load_cubemap_rgb(const char* path, float* faces, size_t capacity,
                                                              int* size);

/* Writes six GL-ordered float RGB faces of size x size as an OpenEXR ENVMAP_CUBE file.
 * Errors: as hemilight_exr_save_rgb. */
HEMILIGHT_API hemilight_status hemilight_exr_save_cubemap_rgb(const char* path, const float* faces, int size,
                                                              int half_float);

/* ---- cube maps -----------------------------------------------------------------------------------
 * Float RGB cube maps: six faces in OpenGL order (+X, -X, +Y, -Y, +Z, -Z), face-major, each
 * size x size texels, rows along the GL t coordinate, columns along s, RGB interleaved
 * (6 x size x size x 3 floats). Face sizes are 1..16384. A mip chain is its levels one after
 * another, level i of size max(1, size >> i), down to 1 x 1 (hemilight_cubemap_chain_floats).
 * Details, formulas and measured accuracy: include/hemilight/cubemap.hpp, docs/cubemap.md. */

/* How output texels get their directions. Face coordinate u in [-1, 1] of texel x of n:
 * NONE    u = (x + 0.5) 2/n - 1 (texel centres, what GPUs sample);
 * STRETCH u = 2x/(n - 1) - 1 (edge texels of adjacent faces are the same direction; undone
 *         exactly at lookup time by hemilight_cubemap_fixup_lookup);
 * WARP    u = c + a c^3 on the centre c, a = n^2/(n - 1)^3 (edge texels coincide too).
 * At size 1 all three give the face centre. */
typedef enum hemilight_edge_fixup {
  HEMILIGHT_EDGE_FIXUP_NONE = 0,
  HEMILIGHT_EDGE_FIXUP_STRETCH,
  HEMILIGHT_EDGE_FIXUP_WARP
} hemilight_edge_fixup;

/* How hemilight_cubemap_sample filters, like GPUs do. */
typedef enum hemilight_cube_sampling {
  HEMILIGHT_CUBE_SAMPLING_CLAMP_PER_FACE = 0, /* bilinear in one face, clamp-to-edge */
  HEMILIGHT_CUBE_SAMPLING_SEAMLESS            /* bilinear across faces (GL seamless / D3D) */
} hemilight_cube_sampling;

/* Unit direction of texel (x, y) of `face` (0..5) of a size x size face under a mapping.
 * Errors: INVALID_ARGUMENT for size outside [1, 16384], face outside [0, 5], x or y outside
 * [0, size), an unknown fixup, or direction NULL (nothing written). Cost: O(1). */
HEMILIGHT_API hemilight_status hemilight_cubemap_texel_direction(int size, int face, int x, int y,
                                                                 hemilight_edge_fixup fixup, float direction[3]);

/* The runtime lookup fixup for a STRETCH-filtered cube map sampled per face: the two components
 * other than the major one (ties go to x, then y, then z) are multiplied by (size - 1)/size when
 * lod < 0 (a known, fixed size), or by max(0, 1 - 2^lod / size) for an explicit lod >= 0 (size =
 * top-level size; at or past the last mip the scale is 0: the face centre). Exact for STRETCH;
 * for WARP it is off by up to ~0.2 texel between face centre and edge (docs/cubemap.md). The
 * result is not normalised; the zero vector gives the zero vector. Also available as GLSL and HLSL
 * (include/hemilight/shaders/cubemap_fixup.glsl, .hlsl) with the same behaviour.
 * out_direction may alias direction. Errors: INVALID_ARGUMENT for NULL pointers, NaN or Inf in
 * direction or lod, size outside [1, 16384]. */
HEMILIGHT_API hemilight_status hemilight_cubemap_fixup_lookup(const float direction[3], int size, float lod,
                                                              float out_direction[3]);

/* Filters an RGB cube map with the normalised cosine-power lobe of specular power p > 0: each
 * output texel (direction from `fixup`) is sum L W / sum W, W = exact texel solid angle x
 * max(0, cos)^p, over the lobe's extent (cutoff 1e-4), reading a coarser mip of the input where
 * the lobe spans many texels (max relative error ~0.3% against brute force on a sky with a sun,
 * docs/cubemap.md).
 * Uses all cores; deterministic. output holds 6 x output_size^2 x 3 floats and must not overlap
 * input. Errors: INVALID_ARGUMENT for NULL pointers, sizes outside [1, 16384], p not finite and
 * > 0, an unknown fixup, or NaN/Inf in input (output untouched); OUT_OF_MEMORY. */
HEMILIGHT_API hemilight_status hemilight_cubemap_filter_cosine_power(const float* input, int input_size,
                                                                     float specular_power,
                                                                     hemilight_edge_fixup fixup, int output_size,
                                                                     float* output);

/* Irradiance E(n) = integral of L max(0, n.w) dw per output texel (a uniform map of radiance L
 * gives pi L). use_sh = 0: the cosine-lobe filter (quadrature over the input mip of 16 x 16);
 * use_sh = 1: the 9-coefficient SH fast path (exact for radiance in SH bands 0-2, otherwise SH
 * truncation error). Errors as hemilight_cubemap_filter_cosine_power. */
HEMILIGHT_API hemilight_status hemilight_cubemap_filter_irradiance(const float* input, int input_size,
                                                                   hemilight_edge_fixup fixup, int output_size,
                                                                   int use_sh, float* output);

/* Number of floats and levels of an RGB mip chain whose top level has size `size` (levels down to
 * 1 x 1). Either output may be NULL. Errors: INVALID_ARGUMENT for size outside [1, 16384]. */
HEMILIGHT_API hemilight_status hemilight_cubemap_chain_floats(int size, size_t* floats, int* levels);

/* A radiance mip chain (layout above) from an RGB cube map: level i is the cosine-power filter
 * with the gloss mapping p_i = (size_i / (2 lobe_texels))^2, i.e. the lobe's width 1/sqrt(p)
 * equals lobe_texels texels of that level (lobe_texels <= 0 means 1). capacity: floats available
 * at output (at least hemilight_cubemap_chain_floats(output_size)). Errors as
 * hemilight_cubemap_filter_cosine_power, and INVALID_ARGUMENT when capacity is too small or
 * lobe_texels is NaN/Inf. */
HEMILIGHT_API hemilight_status hemilight_cubemap_filter_mip_chain(const float* input, int input_size,
                                                                  hemilight_edge_fixup fixup, int output_size,
                                                                  float lobe_texels, float* output, size_t capacity);

/* Samples an RGB cube map or mip chain (level_count levels, layout above, top-level size `size`)
 * along `direction` (need not be unit) at an explicit lod (clamped to [0, level_count - 1],
 * trilinear between levels), bilinear per face or seamless. apply_fixup = 1 first transforms the
 * direction with hemilight_cubemap_fixup_lookup(direction, size, lod) (lod < 0 is read as the
 * fixed-size form and samples level 0): use it for STRETCH-filtered maps. Errors:
 * INVALID_ARGUMENT for NULL pointers, size outside [1, 16384], level_count outside
 * [1, levels of size], NaN/Inf direction or lod, a zero direction, an unknown sampling. */
HEMILIGHT_API hemilight_status hemilight_cubemap_sample(const float* chain, int size, int level_count,
                                                        const float direction[3], float lod,
                                                        hemilight_cube_sampling sampling, int apply_fixup,
                                                        float rgb[3]);

#ifdef __cplusplus
}
#endif

#endif /* HEMILIGHT_H */
