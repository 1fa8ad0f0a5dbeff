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
 *   - On HEMILIGHT_OK every output is finite. Radiance (triangles, skies, environment maps) and
 *     light colours are limited to 1e30 so that sums of them stay finite; a result that would
 *     still overflow float (a light of huge intensity next to a point) fails with
 *     INVALID_ARGUMENT ("... overflows float") and writes nothing.
 *   - Coordinates of vertices, lights and query points are limited to 1e18 in magnitude.
 *   - Directions and positions are float[3] (x, y, z); frames are right-handed.
 *   - Radiance is in W m^-2 sr^-1 (or any consistent unit); irradiance is the integral of
 *     L cos(theta) d omega, so a uniform sky of radiance L gives pi L. No hidden 1/pi.
 *   - Images are float, channels interleaved, rows one after another, row 0 first; cube maps are
 *     six faces in OpenGL order (+X, -X, +Y, -Y, +Z, -Z), face-major, each size x size texels with
 *     x along the GL s coordinate and y along t.
 *   - Thread safety: every function may be called from any thread; objects are immutable after
 *     creation unless a function says otherwise.
 *   - Arrays and counts (every entry that takes an array with a count): every argument is checked
 *     whatever the counts, so a count of 0 never hides a bad one (a NULL scene, an invalid N or
 *     thread_count fails with count 0 as with count 1000). An array may be NULL only when its
 *     count is 0. With valid arguments, count 0 succeeds and writes nothing (the batch, the
 *     probes) or makes an empty set (hemilight_scene_create, hemilight_scene_with_lights, a bake
 *     mesh without vertices, options->light_count); an entry that needs elements says so in its
 *     Errors (hemilight_cache_irradiance: count 0; the bakes: mesh_count 0, page_count 0).
 *
 * Structs that grow (what stays compatible)
 *   - hemilight_cache_options, hemilight_cache_stats, hemilight_bake_options,
 *     hemilight_bake_stats, hemilight_bake_scene_desc, hemilight_unwrap_options,
 *     hemilight_unwrap_stats, hemilight_bake_shard_info and hemilight_bake_pass_state_info begin
 *     with size_t struct_size. Their _init functions are inline (below)
 *     and record the sizeof the program was compiled with; call one before use.
 *   - A later minor version only appends fields to them, each new field starting at or after the
 *     previous version's sizeof. The library reads the fields that lie within the caller's
 *     struct_size and takes the documented defaults for the others, and writes statistics only
 *     within it. So a program built against this header runs against every later library with the
 *     same SOVERSION (libhemilight_c.so.1) without a rebuild.
 *   - A struct_size below sizeof(size_t) (not initialised) or above what the library knows (a
 *     program built against a newer header than the library) is refused with INVALID_ARGUMENT.
 *   - Structs passed in arrays (hemilight_bake_mesh, hemilight_bake_material, hemilight_light,
 *     hemilight_irradiance, hemilight_bake_placement, hemilight_bake_page, hemilight_opacity,
 *     hemilight_alpha_texture, hemilight_mesh_opacity) and every function signature stay as they are for an SOVERSION; new
 *     data would come through new functions or arrays. The SOVERSION changes only when that
 *     promise is broken.
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
#define HEMILIGHT_VERSION_MINOR 15
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
 * a directory, unreadable, truncated or corrupt file, a header attribute larger than the file),
 * UNSUPPORTED (no R, G, B channels, or subsampled ones), OUT_OF_MEMORY (over 2^28 pixels). */
HEMILIGHT_API hemilight_status hemilight_exr_info(const char* path, int* width, int* height, int* is_cubemap);

/* Reads an EXR image as float RGB into rgb (capacity in floats, at least width x height x 3).
 * width and height (may be NULL) receive the size. Errors: as hemilight_exr_info, and
 * INVALID_ARGUMENT when rgb is NULL or capacity is too small (nothing is written then). The size
 * in the header is compared with capacity before any pixel is decoded: a refusal costs the
 * header's reading alone, whatever size the file claims. */
HEMILIGHT_API hemilight_status hemilight_exr_load_rgb(const char* path, float* rgb, size_t capacity, int* width,
                                                      int* height);

/* Writes float RGB pixels (width x height x 3 floats) as an EXR file, 32-bit float channels or,
 * when half_float is nonzero, 16-bit half. The file is replaced atomically: on failure any
 * existing file is left as it was. Errors: INVALID_ARGUMENT (NULL, sizes <= 0, width x height over
 * 2^28 pixels; non-finite values are allowed), IO (cannot write). */
HEMILIGHT_API hemilight_status hemilight_exr_save_rgb(const char* path, const float* rgb, int width, int height,
                                                      int half_float);

/* Reads an ENVMAP_CUBE EXR (size x 6 size) as six GL-ordered faces of float RGB into faces
 * (capacity in floats, at least 6 x size x size x 3); size receives the face size (may be NULL).
 * Errors: as hemilight_exr_load_rgb, and UNSUPPORTED when the image is not 6x as tall as wide or
 * is a latlong map. The shape and the capacity are checked from the header, before any pixel is
 * decoded. */
HEMILIGHT_API hemilight_status hemilight_exr_load_cubemap_rgb(const char* path, float* faces, size_t capacity,
                                                              int* size);

/* Writes six GL-ordered float RGB faces of size x size as an OpenEXR ENVMAP_CUBE file.
 * Errors: as hemilight_exr_save_rgb, the size outside [1, 6688]. */
HEMILIGHT_API hemilight_status hemilight_exr_save_cubemap_rgb(const char* path, const float* faces, int size,
                                                              int half_float);

/* ---- scenes ------------------------------------------------------------------------------------
 * A scene is an immutable set of triangles, each with a constant outgoing radiance (RGB), and a
 * constant sky radiance seen where nothing is hit. It may be shared by any number of threads.
 * Front faces wind counter-clockwise: their normal is (v1 - v0) x (v2 - v0). Triangles made here
 * are one-sided: a hemicube texel that sees a back face gets radiance 0 and counts in
 * backface_fraction. Zero-area triangles are accepted and never drawn. */
typedef struct hemilight_scene hemilight_scene;

/* Creates a scene, copying the arrays (the caller may free them afterwards):
 *   positions          3 * vertex_count floats (x, y, z), finite, at most 1e18 in magnitude
 *   indices            3 * triangle_count vertex indices, each < vertex_count
 *   triangle_radiance  3 * triangle_count floats (RGB per triangle), in [0, 1e30]
 *   sky_radiance       3 floats, in [0, 1e30]
 * An empty scene (vertex_count = triangle_count = 0; the arrays may then be NULL) is valid: every
 * texel sees the sky. On success *out receives the scene; release it with hemilight_scene_release.
 * Errors (nothing written to *out): INVALID_ARGUMENT for a NULL pointer with a nonzero count, a
 * NULL out or sky_radiance, counts over 2^31 - 1, positions NaN/Inf or beyond 1e18 in magnitude,
 * out-of-range indices, radiance negative, non-finite or above 1e30; the message names the
 * argument and the index, e.g.
 * "indices[17] = 900 is out of range: 12 vertices". OUT_OF_MEMORY if allocation fails.
 * Cost: O(T log^2 T) for T triangles (building the culling hierarchy); ~100 bytes per triangle. */
HEMILIGHT_API hemilight_status hemilight_scene_create(const float* positions, size_t vertex_count,
                                                      const uint32_t* indices, size_t triangle_count,
                                                      const float* triangle_radiance, const float sky_radiance[3],
                                                      hemilight_scene** out);

/* Releases a scene made by hemilight_scene_create or hemilight_scene_with_environment. NULL is
 * fine (does nothing). */
HEMILIGHT_API void hemilight_scene_release(hemilight_scene* scene);

/* A new scene handle with the same geometry as `scene` (shared, not copied: releasing either
 * handle keeps the other valid) whose sky is an environment cube map: texels that hit nothing see
 * the map's radiance along their world direction (seamless bilinear) instead of the constant sky.
 * faces_rgb: six faces in OpenGL order (+X, -X, +Y, -Y, +Z, -Z), size x size RGB floats each,
 * face-major, each in [0, 1e30]; copied. Directions are the scene's world axes. Release the new
 * handle with hemilight_scene_release. Errors (nothing written to *out): INVALID_ARGUMENT for NULL
 * arguments, size outside [1, 6688], values negative, non-finite or above 1e30 (the message names
 * the index).
 * Cost: O(6 size^2) to copy the map. */
HEMILIGHT_API hemilight_status hemilight_scene_with_environment(const hemilight_scene* scene, const float* faces_rgb,
                                                                int size, hemilight_scene** out);

/* Since 0.15. A new scene handle with the geometry, sky and lights of `scene` (shared, not copied:
 * releasing either handle keeps the other valid) whose hemicubes use exact edge coverage
 * (edge_coverage = 1) or point sampling (0, what hemilight_scene_create gives): a hemicube texel
 * that a hard edge crosses (a mesh boundary, a change of material, a silhouette) gets the exact
 * covered fraction of its weight instead of what its centre sees, so the irradiance no longer
 * jumps with where edges fall (docs/raster.md, "Exact edge coverage"). It applies to the entries
 * that have no options struct: hemilight_sample_irradiance, the samplers, the batch and the probes;
 * hemilight_cache_irradiance uses it when the scene has it or its options ask for it. The other
 * scene_with_* entries keep the setting. Errors (nothing written to *out): INVALID_ARGUMENT for
 * NULL scene or out, edge_coverage not 0 or 1. Cost: O(1) here; each hemicube then costs about
 * 1.7x (rooms) to 28x (a terrain seen from its own surface) at N = 64, and binding a rasterizer
 * to the scene (hemilight_sampler_create; hemilight_sample_irradiance on every call, so prefer a
 * sampler) sorts the scene's edges, O(T log T) for T triangles. */
HEMILIGHT_API hemilight_status hemilight_scene_with_edge_coverage(const hemilight_scene* scene, int edge_coverage,
                                                                  hemilight_scene** out);

/* ---- opacity: alpha-tested and translucent triangles --------------------------------------------
 * Since 0.15. Each triangle lets light through in one of three ways (include/hemilight/scene.hpp,
 * surface_opacity): opaque (the default: hemicubes see it, shadow rays stop at it), alpha-tested
 * (glTF alphaMode MASK: present where its alpha is at least its cutoff, absent elsewhere; decided
 * per hemicube texel at the texel's centre and per shadow ray at its hit point) or translucent
 * (glTF BLEND, KHR_materials_transmission: lets `transmittance` of the light behind it through,
 * per channel, and adds its own radiance, attenuated by the translucent layers in front of it; it
 * never hides what lies behind it from a texel's depth, distances or back-face flags; shadow rays
 * multiply the transmittances they cross). Scenes take opacity through
 * hemilight_scene_with_opacity, scene bakes through hemilight_bake_scene_desc::mesh_opacity;
 * hemilight_bake_lightmap(_directional) bakes opaque triangles (its mesh struct does not grow: a
 * scene bake with one page holding every mesh gives bitwise the same bake, with opacity).
 * Cost: see-through triangles are kept out of the culling hierarchy and drawn after the opaque
 * ones (alpha-tested: four texel reads per covered hemicube texel); an alpha-tested triangle
 * whose alpha is below its cutoff and that reads no texture is left out altogether (it is never
 * present). */
/* Since 0.15. The opacity modes (hemilight_opacity::mode). */
typedef enum hemilight_opacity_mode {
  HEMILIGHT_OPAQUE = 0,       /* blocks all light (the default) */
  HEMILIGHT_ALPHA_TESTED = 1, /* present where alpha x the alpha texture's value >= alpha_cutoff, absent elsewhere */
  HEMILIGHT_TRANSLUCENT = 2   /* lets transmittance of the light behind it through */
} hemilight_opacity_mode;

/* Since 0.15. How one triangle lets light through. Fields its mode does not use are ignored (not
 * checked), so a zeroed struct is a valid opaque one. Initialise with HEMILIGHT_OPACITY_DEFAULT or
 * hemilight_opacity_init (opaque, alpha 1, alpha_cutoff 0.5, alpha_texture -1, transmittance 0). */
typedef struct hemilight_opacity {
  int mode;               /* a hemilight_opacity_mode value (an int: any value is checked) */
  float alpha;            /* ALPHA_TESTED: the alpha factor, in [0, 1] (glTF baseColorFactor's alpha), multiplied by
                             the alpha texture's value where there is one (default 1) */
  float alpha_cutoff;     /* ALPHA_TESTED: present where alpha (x texture) >= alpha_cutoff, in [0, 1] (glTF
                             alphaCutoff; default 0.5) */
  int alpha_texture;      /* ALPHA_TESTED: index of its alpha texture (the alpha_textures passed with it), or -1 (default):
                             the factor alone decides, for the whole triangle. A texture needs texcoords. */
  float transmittance[3]; /* TRANSLUCENT: the fraction of the light behind it that passes, per channel (RGB), each in
                             [0, 1] (default 0) */
} hemilight_opacity;

/* Since 0.15. The defaults of hemilight_opacity, as an initialiser:
 *   hemilight_opacity o = HEMILIGHT_OPACITY_DEFAULT; */
#define HEMILIGHT_OPACITY_DEFAULT { HEMILIGHT_OPAQUE, 1.0f, 0.5f, -1, { 0.0f, 0.0f, 0.0f } }

/* Since 0.15. Fills *opacity with the defaults (HEMILIGHT_OPACITY_DEFAULT). NULL is ignored. */
HEMILIGHT_API void hemilight_opacity_init(hemilight_opacity* opacity);

/* Since 0.15. An 8-bit single-channel alpha texture (value / 255) for alpha-tested triangles,
 * read bilinearly with repeat wrapping (glTF's default sampler) at the texture coordinates
 * interpolated over the triangle: texel (x, y) (x the column, y the row of `values`) has its
 * centre at ((x + 0.5) / width, (y + 0.5) / height): u grows with the column, v with the row
 * (glTF's convention: v = 0 is the image's first row). Copied (scenes) or read during the call
 * only (bakes). */
typedef struct hemilight_alpha_texture {
  const uint8_t* values; /* width x height values, row-major, row 0 first */
  int width, height;     /* texels, each in [1, 16384] */
} hemilight_alpha_texture;

/* Since 0.15. The opacity of one mesh of a scene bake (hemilight_bake_scene_desc::mesh_opacity).
 * A zeroed struct is an opaque mesh. */
typedef struct hemilight_mesh_opacity {
  const hemilight_opacity* opacities; /* the mesh's triangle_count opacities, or NULL: `opacity` for every triangle */
  hemilight_opacity opacity;
  const float* texcoords;             /* NULL, or 2 * vertex_count floats (u, v), finite: where the mesh's alpha textures are
                                         read (glTF TEXCOORD_0; not the lightmap UVs). Required when a triangle of the mesh
                                         names an alpha texture. */
} hemilight_mesh_opacity;

/* Since 0.15. A new scene handle with the triangles, sky or environment, lights and edge coverage
 * of `scene`, whose triangle i lets light through as opacities[i] says (triangle_count entries:
 * the count given to hemilight_scene_create; NULL only when it is 0). Any opacity `scene` had is
 * replaced; `scene` is unchanged and releasing either handle keeps the other valid. Unlike the
 * other scene_with_* entries the geometry is not shared: a new scene is built, and the lights' ray
 * structure for it when `scene` has lights.
 *   texcoords          NULL, or 2 * vertex_count floats (u, v) per vertex, finite: where the alpha
 *                      textures are read; required when an opacity names a texture, copied then
 *   alpha_textures     alpha_texture_count textures (NULL when the count is 0), copied
 * Applies to every entry that takes the scene: hemilight_sample_irradiance, the samplers, the
 * batch, the probes, hemilight_cache_irradiance.
 * Errors (nothing written to *out; the message names the argument, the index and the field, e.g.
 * "hemilight_scene_with_opacity: opacities[5].alpha_cutoff = 1.5 is outside [0, 1]"):
 * INVALID_ARGUMENT for NULL scene or out, NULL opacities with triangles, NULL alpha_textures with a
 * count, a mode that is not 0, 1 or 2, an alpha, alpha_cutoff or transmittance outside [0, 1] or
 * NaN, an alpha_texture that is not -1 or below alpha_texture_count, a texture named without
 * texcoords, a NaN or infinite texcoord, a texture of a side outside [1, 16384] or with NULL
 * values; OUT_OF_MEMORY; with lights, as hemilight_scene_with_lights when Embree fails.
 * Cost: as hemilight_scene_create (O(T log^2 T) for T triangles), plus copies of the textures
 * (width x height bytes each) and the texcoords (8 bytes per vertex), plus the ray structure with
 * lights (hemilight_scene_with_lights). */
HEMILIGHT_API hemilight_status hemilight_scene_with_opacity(const hemilight_scene* scene, const hemilight_opacity* opacities,
                                                            const float* texcoords, const hemilight_alpha_texture* alpha_textures,
                                                            size_t alpha_texture_count, hemilight_scene** out);

/* ---- lights ------------------------------------------------------------------------------------ */

/* Analytic lights (include/hemilight/lights.hpp, docs/lights.md). Lights are not geometry:
 * hemicubes never see them and shadow rays never hit them. Their direct irradiance (closed forms,
 * shadows from shadow rays against the scene's triangles, either side) is added to what the
 * hemicubes gather by hemilight_sample_irradiance and hemilight_cache_irradiance (scenes made by
 * hemilight_scene_with_lights) and by the bakes (hemilight_bake_options::lights), at every point:
 * never interpolated. */
typedef enum hemilight_light_type {
  HEMILIGHT_LIGHT_DIRECTIONAL = 0, /* the sun: a disc of directions */
  HEMILIGHT_LIGHT_POINT = 1,       /* a point, or a sphere with radius */
  HEMILIGHT_LIGHT_SPOT = 2,        /* a point light with a cone (glTF KHR_lights_punctual falloff) */
  HEMILIGHT_LIGHT_RECT = 3         /* a one-sided emitting rectangle */
} hemilight_light_type;

/* One light. Fields a type does not use are ignored but must be finite. Units: metres (scene
 * units), radians, W. */
typedef struct hemilight_light {
  hemilight_light_type type;
  float color[3];      /* DIRECTIONAL: W/m^2 on a plane facing it; POINT, SPOT: W/sr; RECT: W/m^2/sr;
                          each in [0, 1e30] */
  float position[3];   /* POINT, SPOT: position; RECT: centre; each at most 1e18 in magnitude (all types) */
  float direction[3];  /* DIRECTIONAL: direction of travel; SPOT: axis; RECT: normal of the lit side (any length > 0) */
  float tangent[3];    /* RECT: direction of its width (any length > 0, not parallel to direction) */
  float width, height; /* RECT: size, each > 0 */
  float radius;        /* DIRECTIONAL: angular radius (rad, <= pi/2; the sun: 0.00465); POINT, SPOT: sphere radius; 0 = hard */
  float spot_inner, spot_outer; /* SPOT: half-angles (rad), 0 <= inner <= outer <= pi/2; full inside inner, 0 outside outer,
                                   between: clamp((cos a - cos outer) / (cos inner - cos outer), 0, 1)^2 */
  int casts_shadows;   /* 1: shadow rays decide visibility; 0: the light reaches every point in front of it */
} hemilight_light;

/* Fills *light with the defaults of `type`: color (1, 1, 1), position (0, 0, 0), direction
 * (0, -1, 0), tangent (1, 0, 0), width = height = 1, radius 0 (hard), spot_inner 0, spot_outer
 * pi/4 (glTF's default), casts_shadows 1. NULL is ignored; an unknown type is stored as given (and
 * rejected where the light is used). */
HEMILIGHT_API void hemilight_light_init(hemilight_light* light, hemilight_light_type type);

/* A new scene handle with the geometry and sky of `scene` (shared, not copied: releasing either
 * handle keeps the other valid) and `count` lights (copied; they replace any lights of `scene`;
 * count 0 gives a scene without lights, lights may then be NULL). Release it with
 * hemilight_scene_release. Errors (nothing written to *out): INVALID_ARGUMENT for NULL scene or
 * out, NULL lights with count > 0, and a bad light, the message naming its index and field
 * ("hemilight_scene_with_lights: lights[2].spot_outer = 1.7 is past pi/2"): an unknown type, NaN
 * or Inf in any field, a position beyond 1e18 in magnitude, a colour negative or above 1e30, a
 * zero direction (DIRECTIONAL, SPOT, RECT), a negative radius (all but RECT) or a DIRECTIONAL
 * radius past pi/2, a negative spot_inner, spot angles out of order or past pi/2, RECT width or
 * height <= 0 or a tangent zero or parallel to the normal (within 1e-3 rad), casts_shadows not 0
 * or 1;
 * OUT_OF_MEMORY, UNSUPPORTED or INTERNAL if the shadow rays' acceleration structure (Embree) cannot
 * be built. Cost: O(count), and with lights the first time for this geometry the ray structure
 * (about 0.3 ms per 1,000 triangles, ~100 bytes per triangle; include/hemilight/rays.hpp). */
HEMILIGHT_API hemilight_status hemilight_scene_with_lights(const hemilight_scene* scene, const hemilight_light* lights,
                                                           size_t count, hemilight_scene** out);

/* ---- irradiance at a point: render + integrate ------------------------------------------------ */

/* What one hemicube sees, reduced. Gradients follow the irradiance-caching convention, per colour
 * channel c:  E_c(x', n') ~= E_c + (n x n') . rotation_gradient[c] + (x' - x) . translation_gradient[c],
 * both world-space vectors in the tangent plane (translation gradient: the great-arc wall
 * estimator, docs/integration.md). */
typedef struct hemilight_irradiance {
  float irradiance[3];              /* E per channel: integral of L cos(theta) d omega (uniform sky L: pi L) */
  float rotation_gradient[3][3];    /* [channel][xyz], world space */
  float translation_gradient[3][3]; /* [channel][xyz], world space, per scene unit */
  float harmonic_mean_distance;     /* split-sphere distance (scene units); +inf if nothing was hit */
  float min_distance;               /* nearest hit (scene units); +inf if nothing was hit */
  float backface_fraction;          /* projected-solid-angle fraction seeing back faces, [0, 1] */
} hemilight_irradiance;

/* Renders the hemicube of resolution N at `position` with normal `normal` and integrates it. With
 * a scene that has lights (hemilight_scene_with_lights), irradiance also holds their direct
 * irradiance at the point (shadow rays from the point offset along the normal by 1e-4 x the
 * scene's size); the gradients, distances and backface_fraction are the hemicube's alone.
 * The normal need not be unit length (it is normalised, in double: any finite nonzero vector works,
 * 1e-30 or 1e30 long alike) but must be finite and nonzero. The point
 * itself does not see the surface it lies on; offset it from the surface if that surface is not in
 * the scene. The hemicube's frame is built from the normal (deterministic, no roll).
 * Errors (out untouched): INVALID_ARGUMENT for NULL scene/position/normal/out, NaN/Inf position or
 * normal, a position beyond 1e18 in magnitude, a zero normal, N odd or outside [2, 4096], a result
 * that overflows float (a light too close: "Conventions").
 * Cost: one hemicube (Cornell box, N = 64: about 25 us on one core, docs/capi.md). Each thread
 * keeps a context for the last N it used up to N = 512 (scratch and a reference to its tables:
 * 342 N^2 bytes, 1.3 MiB at N = 64, 86 MiB at N = 512; hemilight_release_tables frees it)
 * between calls, but no reference to the scene; the first call on a thread for a new N builds it
 * (~5 ms at N = 64). Above N = 512 every call makes its own context (the tables come from the
 * table cache while they fit its budget).
 * For many points use hemilight_sampler_irradiance (one per thread) or the batch below. */
HEMILIGHT_API hemilight_status hemilight_sample_irradiance(const hemilight_scene* scene, const float position[3],
                                                           const float normal[3], int resolution,
                                                           hemilight_irradiance* out);

/* A sampler: one thread's reusable context for hemilight_sampler_irradiance, bound to a scene and a
 * hemicube resolution. It keeps the scene alive: the scene handle may be released while samplers
 * made from it live. A sampler serves one thread at a time; a call made while another thread's call
 * on the same sampler runs is refused (INVALID_ARGUMENT, "in use by another thread") rather than
 * racing. Different samplers of one scene may be used by different threads at once. */
typedef struct hemilight_sampler hemilight_sampler;

/* Creates a sampler for `scene` (its triangles, sky or environment, and lights) at hemicube
 * resolution N. On success *out receives it; release it with hemilight_sampler_release.
 * Errors (nothing written to *out): INVALID_ARGUMENT for NULL scene/out, N odd or outside
 * [2, 4096]; OUT_OF_MEMORY. Cost: the tables for N (~5 ms and 0.5 MB at N = 64; about 40 bytes
 * per hemicube texel, 3 N^2). */
HEMILIGHT_API hemilight_status hemilight_sampler_create(const hemilight_scene* scene, int resolution,
                                                        hemilight_sampler** out);

/* hemilight_sample_irradiance at the sampler's scene and N: bitwise the same result for the same
 * point. Errors (out untouched): INVALID_ARGUMENT for a NULL sampler or out, a point that
 * hemilight_sample_irradiance refuses (or whose result overflows float), a sampler in use by
 * another thread. Cost: one hemicube, nothing else (Cornell box, N = 64: about 25 us on one
 * core). */
HEMILIGHT_API hemilight_status hemilight_sampler_irradiance(hemilight_sampler* sampler, const float position[3],
                                                            const float normal[3], hemilight_irradiance* out);

/* Releases a sampler (NULL is fine); the scene goes when its last handle or sampler goes. */
HEMILIGHT_API void hemilight_sampler_release(hemilight_sampler* sampler);

/* hemilight_sample_irradiance at `count` points on `thread_count` threads (0 = all cores):
 * positions and normals are 3 * count floats, out receives count results, each bitwise what
 * hemilight_sample_irradiance gives for that point, for any thread count. count = 0 checks the
 * other arguments and does nothing (the arrays may then be NULL: "Arrays and counts" at the top).
 * Errors (nothing written to out): INVALID_ARGUMENT for a NULL scene, or NULL arrays with count > 0,
 * count over 2^31 - 1, N odd or outside [2, 4096], thread_count < 0, and any point that
 * hemilight_sample_irradiance refuses, named by its index ("point 17: normal (0, 0, 0) has no
 * direction", "point 3: the irradiance overflows float"); OUT_OF_MEMORY. Cost: count hemicubes
 * over the threads, plus the tables per thread; about 100 bytes per point of temporary memory. */
HEMILIGHT_API hemilight_status hemilight_sample_irradiance_batch(const hemilight_scene* scene, const float* positions,
                                                                 const float* normals, size_t count, int resolution,
                                                                 int thread_count, hemilight_irradiance* out);

/* ---- light probes -------------------------------------------------------------------------------- */

/* Light probes: the radiance arriving at points in free space, projected on real spherical
 * harmonics up to band 2 (SH9), for lighting moving objects. Per probe i, 27 floats:
 * sh9_rgb[27 i + 3 k + c], channel c = R, G, B, coefficient k in the order (l, m) = (0,0),
 * (1,-1), (1,0), (1,1), (2,-2), (2,-1), (2,0), (2,1), (2,2) of the basis
 *   0.282095, 0.488603 y, 0.488603 z, 0.488603 x, 1.092548 xy, 1.092548 yz,
 *   0.315392 (3z^2 - 1), 1.092548 xz, 0.546274 (x^2 - y^2)
 * (world axes, unit direction (x, y, z)); coefficient = integral over the whole sphere of
 * L Y_k d omega: a uniform sky of radiance L gives c_0 = 2 sqrt(pi) L = 3.5449 L and the rest 0.
 * Made from two hemicubes of resolution N per probe (up +z and down -z: the six faces of a cube)
 * with each basis function integrated over each texel, plus the scene's lights (each a point
 * source from the direction of its visible light, shadows included: exact for hard point, spot and
 * sun lights). docs/probes.md has the figures.
 * A probe inside closed geometry sees back faces; hemilight_sample_probes_with_backfaces reports
 * the solid-angle fraction of its sphere that does (near 1 inside; drop probes above ~0.1).
 * Errors (nothing written): INVALID_ARGUMENT for a NULL scene, NULL arrays with count > 0, count
 * over 2^31 - 1, N odd or outside [2, 4096], thread_count < 0, a position not finite or beyond 1e18
 * in magnitude or a probe that overflows float, named by its index ("point 7: position (0, nan, 1)
 * is not finite or beyond 1e18"); OUT_OF_MEMORY.
 * Deterministic: bitwise the same for any thread_count (0 = all cores). count = 0 checks the other
 * arguments and does nothing (the arrays may then be NULL: "Arrays and counts" at the top).
 * Cost: 2 hemicubes and their projections per probe plus the lights' shadow rays (Cornell box,
 * N = 64: ~7k probes/s per core, 14k on two; docs/probes.md); tables of 36 N^2 floats per N,
 * kept between calls within the table budget (hemilight_set_table_budget). */
HEMILIGHT_API hemilight_status hemilight_sample_probes(const hemilight_scene* scene, const float* positions, size_t count,
                                                       int resolution, int thread_count, float* sh9_rgb);

/* hemilight_sample_probes, also writing backface_fraction[i] in [0, 1] per probe (count floats):
 * the fraction of the sphere's solid angle that sees back faces of one-sided triangles. Errors as
 * hemilight_sample_probes, plus a NULL backface_fraction with count > 0. */
HEMILIGHT_API hemilight_status hemilight_sample_probes_with_backfaces(const hemilight_scene* scene, const float* positions,
                                                                      size_t count, int resolution, int thread_count,
                                                                      float* sh9_rgb, float* backface_fraction);

/* Irradiance (W/m^2, RGB) for a surface normal from one probe's 27 coefficients: the
 * clamped-cosine convolution E(n) = sum_k A_l c_k Y_k(n), A_0 = pi, A_1 = 2 pi / 3, A_2 = pi / 4.
 * The normal need not be unit length. The band limit rings around small bright sources: for a
 * 5-degree source whose exact irradiance facing it is 1, SH9 gives 1.062 facing it, 0.462 at
 * 60 degrees (exact 0.5), 0.095 at 90 and 0.062 opposite (exact 0); results may be slightly
 * negative. Errors (irradiance untouched): INVALID_ARGUMENT for NULL arguments, non-finite
 * coefficients or normal, a zero normal, or a result that overflows float. Cost: ~30 flops. */
HEMILIGHT_API hemilight_status hemilight_sh9_irradiance(const float sh9_rgb[27], const float normal[3], float irradiance[3]);

/* ---- irradiance cache ---------------------------------------------------------------------------- */

/* Progress callback: called from the calling thread with the fraction of points done, [0, 1];
 * return nonzero to go on, 0 to cancel (the call then returns HEMILIGHT_ERROR_CANCELLED and
 * writes nothing). */
typedef int (*hemilight_progress_fn)(void* user, float fraction);

/* Interpolation weight of the irradiance cache. */
typedef enum hemilight_cache_weight {
  HEMILIGHT_CACHE_WEIGHT_WARD = 0,                 /* 1 / (d / R + sqrt(1 - n.n_i)), used where > 1 / a */
  HEMILIGHT_CACHE_WEIGHT_TABELLION_LAMORLETTE = 1, /* 1 - max(d / (R / 2), angle term) / (2a), used where > 0 */
  HEMILIGHT_CACHE_WEIGHT_WARD_CONTINUOUS = 2       /* since 0.6: Ward's weight less 1 / a, used where Ward's
                                                      > 1 / a: the same records as WARD, but each one's weight
                                                      falls to 0 at the edge of its reach, so the result is
                                                      continuous there (lower error, docs/cache.md) */
} hemilight_cache_weight;

/* Options of hemilight_cache_irradiance; fill with hemilight_cache_options_init, then change what
 * you need. The fields come in two groups; since fields are only ever appended ("Structs that
 * grow"), the groups cannot be contiguous in memory, so the comments below mark each field's:
 *   - what an engine tunes: resolution, error_threshold, min_radius, max_radius, use_gradients,
 *     thread_count, progress, progress_user, weight, invalid_backface_fraction, second_order,
 *     edge_coverage;
 *   - expert: kept for comparisons; see cache_options in C++ (include/hemilight/cache.hpp):
 *     gradient_radius_limit, neighbour_clamp, shrink_disagreeing, refine_disagreement,
 *     second_opinion, nearby_opinion, sole_record_reach, extrapolate_wall_depth. Each switches one
 *     placement rule or estimator so that its effect can be measured; the defaults are the
 *     measured best (docs/cache.md) and an engine leaves them alone. */
typedef struct hemilight_cache_options {
  size_t struct_size;     /* sizeof(hemilight_cache_options) as the caller was built: set by
                             hemilight_cache_options_init (see "Structs that grow" at the top) */
  /* ---- what an engine tunes ---- */
  int resolution;         /* hemicube N, even, 2..4096 (default 64) */
  float error_threshold;  /* Ward's a, [0.001, 1]: larger = fewer hemicubes, more error (default 0.2) */
  float min_radius, max_radius; /* record radius limits in scene units, each finite and >= 0, min <=
                                   max when both are set; 0 = automatic (defaults): min = (median
                                   point spacing) / a, max = 0.2 x the points' extent */
  int use_gradients;      /* 0 or 1: interpolate with rotation and translation gradients (default 1) */
  int thread_count;       /* >= 0; 0 = all cores (default 0) */
  hemilight_progress_fn progress; /* may be NULL (default NULL) */
  void* progress_user;    /* passed to progress */
  hemilight_cache_weight weight;  /* since 0.5: interpolation weight (default HEMILIGHT_CACHE_WEIGHT_WARD) */
  /* ---- expert: kept for comparisons; see cache_options in C++ (include/hemilight/cache.hpp) ----
   * Since 0.5: the placement rules and radius limits, each switchable so that its effect can be
   * measured (docs/cache.md). Leave them at their defaults. */
  int gradient_radius_limit;      /* 0 or 1: R <= E / |translation gradient| (default 1) */
  int neighbour_clamp;            /* 0 or 1: R_i <= R_j + |x_i - x_j| (default 1) */
  int shrink_disagreeing;         /* 0 or 1: shrink neighbours whose gradients disagree (default 1) */
  int refine_disagreement;        /* 0 or 1: points whose covering records disagree by more than a stay
                                     open (default 1) */
  float second_opinion;           /* finite, >= 0, 0 = off: a single covering record's first-order term must stay
                                     under second_opinion x a (default 0.25) */
  float nearby_opinion;           /* [0, 16], 0 = off: nearby records that do not cover a singly covered
                                     point must agree with it, within this many finest spacings (default 2) */
  float sole_record_reach;        /* (0, 1], 1 = off: a singly covered point must lie inside this fraction
                                     of the record's reach (default 0.99) */
  float invalid_backface_fraction; /* engine: [0, 1]: samples seeing more back faces are invalid, i.e. the
                                      point is inside geometry (default 0.1) */
  int extrapolate_wall_depth;     /* expert; 0 or 1: the hemicubes' translation gradients take each texel
                                     wall's depth extrapolated from the nearer texel (more accurate where
                                     planes are seen at grazing angles; docs/integration.md) (default 0) */
  /* ---- what an engine tunes (continued) ---- */
  int second_order;               /* since 0.7; 0 or 1: after placement, each record gets a Hessian fitted
                                     from its neighbours' gradients (scaled by how well it predicts their
                                     values) and the interpolation adds its quadratic term; the same
                                     records and hemicubes, lower error (docs/cache.md) (default 1) */
  int reserved0;                  /* padding, not read: keeps edge_coverage past the earlier layout's
                                     sizeof on every ABI (its tail padding is not the caller's to fill) */
  int edge_coverage;              /* since 0.14; 0 or 1: the hemicubes give a texel that a hard edge (a
                                     boundary, a change of material, a silhouette) crosses the exact
                                     covered fraction of its weight instead of what its centre sees (no
                                     edge aliasing: an emitter's irradiance to about 1e-4 where point
                                     sampling is off by up to 18% at N = 16; docs/raster.md, "Exact edge
                                     coverage"). Render time 1.7x on tessellated rooms to 28x on terrain
                                     seen from itself at N = 64 (default 0) */
} hemilight_cache_options;

/* Fills the first struct_size bytes of options with the defaults above and sets
 * options->struct_size = struct_size (fields past it are not touched). NULL, or a struct_size below
 * sizeof(size_t), is ignored. Call it through hemilight_cache_options_init. */
HEMILIGHT_API void hemilight_cache_options_init_sized(hemilight_cache_options* options, size_t struct_size);
/* Fills options with the defaults above (inline: records the caller's sizeof). NULL is ignored. */
static inline void hemilight_cache_options_init(hemilight_cache_options* options) {
  hemilight_cache_options_init_sized(options, sizeof *options);
}

typedef struct hemilight_cache_stats {
  size_t struct_size;     /* sizeof as the caller was built: set by hemilight_cache_stats_init */
  size_t hemicubes;       /* hemicubes rendered */
  size_t records;         /* cache records kept */
  double seconds;         /* wall time */
  size_t invalid_samples; /* hemicubes rejected because they saw > 10% back faces (inside geometry) */
} hemilight_cache_stats;

/* Zeroes stats and sets stats->struct_size (call before passing stats to a function that fills
 * it; the library writes only the fields that fit in struct_size). NULL is ignored. */
HEMILIGHT_API void hemilight_cache_stats_init_sized(hemilight_cache_stats* stats, size_t struct_size);
static inline void hemilight_cache_stats_init(hemilight_cache_stats* stats) {
  hemilight_cache_stats_init_sized(stats, sizeof *stats);
}

/* Irradiance (RGB) at `count` points (positions and normals: 3 * count floats each; normals unit
 * length within 1e-3) through the irradiance cache: hemicubes are rendered at few points, the
 * rest is interpolated (docs and include/hemilight/cache.hpp). With a scene that has lights, their
 * direct irradiance is computed at every point (shadow rays, never interpolated) and added; the
 * cache interpolates only what the hemicubes gather. A point inside geometry gets the direct light
 * its own shadow rays find (usually none). The result is deterministic: the
 * same input gives bitwise the same output for any thread_count. Points inside geometry (their
 * hemicube sees mostly back faces) are filled from valid records around them.
 * irradiance_rgb receives 3 * count floats; stats may be NULL.
 * Errors (nothing written): INVALID_ARGUMENT for NULL scene/positions/normals/options/output,
 * count 0, positions NaN/Inf or beyond 1e18 in magnitude, points spanning more than 1e18 units
 * (their squared distances must fit in float), non-unit normals, options or struct_size (options,
 * stats) out of range (the message names the field), a result that overflows float; CANCELLED
 * when the progress callback returned 0. */
HEMILIGHT_API hemilight_status hemilight_cache_irradiance(const hemilight_scene* scene, const float* positions,
                                                          const float* normals, size_t count,
                                                          const hemilight_cache_options* options,
                                                          float* irradiance_rgb, hemilight_cache_stats* stats);

/* ---- lightmap baker -------------------------------------------------------------------------------- */

/* Per-triangle material of a baked mesh. */
typedef struct hemilight_bake_material {
  float emission[3]; /* emitted radiance (RGB), each in [0, 1e30] */
  float albedo[3];   /* diffuse reflectance (RGB), each in [0, 1] */
  int two_sided;     /* 0: seen from behind a triangle occludes but is black; 1: both sides look like the front */
} hemilight_bake_material;

/* One mesh of the scene to bake. All meshes share one lightmap (one UV space). Front faces wind
 * counter-clockwise (normal (v1 - v0) x (v2 - v0)). */
typedef struct hemilight_bake_mesh {
  const float* positions;    /* 3 * vertex_count floats, finite, at most 1e18 in magnitude */
  const float* normals;      /* 3 * vertex_count floats (shading normals, finite, any length; where they
                                interpolate to zero the face normal is used), or NULL: face normals */
  const float* lightmap_uvs; /* 2 * vertex_count floats (u, v), each in [0, 1] */
  size_t vertex_count;
  const uint32_t* indices;   /* 3 * triangle_count vertex indices of this mesh (< vertex_count) */
  size_t triangle_count;
  const hemilight_bake_material* materials; /* triangle_count materials, or NULL: `material` for every triangle */
  hemilight_bake_material material;
} hemilight_bake_mesh;

/* Bake options; fill with hemilight_bake_options_init, then change what you need. */
typedef struct hemilight_bake_options {
  size_t struct_size;      /* sizeof(hemilight_bake_options) as the caller was built: set by
                              hemilight_bake_options_init (see "Structs that grow" at the top) */
  int width, height;       /* lightmap size in texels, each 1..8192 (default 256 x 256) */
  int resolution;          /* hemicube N, even, 2..4096 (default 64) */
  int bounces;             /* 1 = direct light only, up to 64 (default 1) */
  int indirect_only;       /* 0 or 1: store everything but the first bounce (default 0) */
  float error_threshold;   /* irradiance cache's Ward a, [0.001, 1] (default 0.2) */
  float min_coverage;      /* texels covered less than this fraction get no sample, [0, 1] (default 0.01) */
  int dilation;            /* rings of dilation around charts, >= 0, or -1 to fill every texel (default 16) */
  int use_cache;           /* 1: irradiance cache; 0: a hemicube at every texel (reference, slow) (default 1) */
  int thread_count;        /* >= 0; 0 = all cores (default 0) */
  float sky_radiance[3];   /* constant radiance seen where nothing is hit, each in [0, 1e30] (default 0) */
  hemilight_progress_fn progress; /* fraction of the whole bake, never decreasing; 0 cancels (default NULL) */
  void* progress_user;
  /* Optional environment sky (default NULL, 0): six faces in OpenGL order (+X, -X, +Y, -Y, +Z, -Z),
   * environment_size x environment_size RGB floats each, face-major (the layout of
   * hemilight_scene_with_environment), each in [0, 1e30], read during the call only. Where a hemicube
   * texel hits nothing it sees the map's radiance along its world direction (seamless bilinear)
   * instead of sky_radiance. environment_size: 1..6688 with a map, 0 without. */
  const float* environment_rgb;
  int environment_size;
  /* Optional lights (default NULL, 0): light_count lights, read during the call only. Their direct
   * irradiance is computed at every sample with shadow rays and added to every bounce, so the
   * bounces carry it; indirect_only drops it with the emitters' first bounce; the directional
   * maps get each light's part along its direction. Checked as hemilight_scene_with_lights does
   * (the message names options->lights[i] and the field). */
  const hemilight_light* lights;
  size_t light_count;
  /* Optional shadow mask (default all -1, NULL, 0): the visibility in [0, 1] of up to four lights
   * per texel, the mask engines with real-time direct light multiply that light by. Channel c of
   * shadow_mask_rgba (width x height RGBA floats, rows as the irradiance) holds the visibility of
   * lights[shadow_mask_lights[c]] (1 for a light that casts no shadow, 0 where it is below the
   * horizon or behind a RECT); -1 leaves channel c 0. Written, dilated, only when the bake succeeds
   * and some index is not -1; shadow_mask_capacity is the floats available there (at least
   * 4 x width x height). An index past light_count, or a mask with no buffer, is INVALID_ARGUMENT. */
  int shadow_mask_lights[4];
  float* shadow_mask_rgba;
  size_t shadow_mask_capacity;
  /* Since 0.14; 0 or 1: every hemicube of the bake with exact edge coverage, as
   * hemilight_cache_options.edge_coverage (default 0). */
  int edge_coverage;
  int reserved1;           /* padding, not read: keeps strict past the earlier layout's sizeof */
  /* Since 0.15; 0 or 1 (default 0). A triangle with 3D area but no lightmap UV area (at most 1e-12
   * of the UV square): 0, it still occludes, gets no texels and is counted in the statistics
   * (no_uv_area_triangles, first_no_uv_area_mesh and _triangle); 1, the bake fails with
   * INVALID_ARGUMENT naming it. Degenerate triangles (no 3D area at float precision: twice their
   * area at most 2^-22 x longest edge x largest coordinate magnitude) are skipped either way:
   * no texels, never occlude, counted (degenerate_triangles). */
  int strict;
  int reserved2;           /* padding, not read: keeps stitch_seams past the earlier layout's sizeof */
  /* Since 0.15; 0 or 1 (default 1). Seam stitching: after the passes, the texels that bilinear
   * lookups read along seams between faces whose shading normals agree within 1 degree (two charts
   * of one mesh, two meshes, two pages) are set by least squares so that both sides agree along the seam, the rest staying near
   * their baked values; every output (irradiance, shadow mask). Seams the two sides cannot see
   * each other across (a wall standing on them), and points where the irradiance jumps across the
   * seam (a hard shadow along it), are left as baked. Counted in
   * hemilight_bake_stats.seam_texels. */
  int stitch_seams;
  int reserved3;           /* padding, not read: keeps ao_distance past the earlier layout's sizeof */
  /* Since 0.15. Ambient occlusion within ao_distance (scene units, finite, >= 0; default 0 = none):
   * per texel the cosine-weighted fraction of the hemisphere that sees no geometry (front or back
   * faces) within that distance, in [0, 1] (1 = open, 0 = fully occluded), from the first bounce's
   * hemicubes (no pass of its own; interpolated by the irradiance cache with the irradiance's
   * weights when use_cache is 1), filled inside geometry, stitched along seams and dilated like the
   * irradiance (docs/bake.md, "Ambient occlusion"). hemilight_bake_lightmap(_directional) writes it
   * to `ao`: width x height floats, one per texel, rows as the irradiance, only when the bake
   * succeeds and ao_distance > 0; ao_capacity is the floats available there (at least
   * width x height). ao_distance negative or not finite, or > 0 with ao NULL or ao_capacity too
   * small, is INVALID_ARGUMENT naming the field; with ao_distance 0, ao and ao_capacity are ignored.
   * Scene bakes write each page's AO through hemilight_bake_scene_desc.ao instead (options->ao is
   * not used there). Cost: one compare and add per hemicube texel in the first bounce; with
   * use_cache 1, the records the cache adds where AO varies faster than the irradiance (14% to 145%
   * more hemicubes in the first bounce on the reference scenes, which also lowers the irradiance's
   * error and so changes its bits); the stitching and dilation of one more image. With ao_distance
   * 0 the bake is bitwise what it was. */
  float ao_distance;
  int reserved4;           /* padding, not read (aligns ao) */
  float* ao;
  size_t ao_capacity;
} hemilight_bake_options;

/* As hemilight_cache_options_init_sized, for bake options. */
HEMILIGHT_API void hemilight_bake_options_init_sized(hemilight_bake_options* options, size_t struct_size);
/* Fills options with the defaults above (inline: records the caller's sizeof). NULL is ignored. */
static inline void hemilight_bake_options_init(hemilight_bake_options* options) {
  hemilight_bake_options_init_sized(options, sizeof *options);
}

typedef struct hemilight_bake_stats {
  size_t struct_size;        /* sizeof as the caller was built: set by hemilight_bake_stats_init */
  size_t sampled_texels;     /* texels that got a sample (coverage >= min_coverage) */
  size_t invalid_texels;     /* sampled texels inside geometry, filled from valid neighbours */
  size_t dilated_texels;     /* empty texels filled by dilation */
  size_t overlapping_texels; /* texels covered by overlapping UV triangles (over 1.001 texel in total) */
  size_t hemicubes;          /* hemicubes rendered, all bounces */
  size_t records;            /* irradiance cache records, all bounces */
  double seconds;            /* wall time */
  /* Since 0.15: the input the bake went past (hemilight_bake_options.strict). */
  size_t degenerate_triangles;       /* triangles without 3D area: skipped (no texels, never occlude) */
  size_t no_uv_area_triangles;       /* triangles with 3D area but no lightmap UV area: occlude, no texels */
  size_t first_no_uv_area_mesh;      /* the first of them: its mesh (index into meshes) and its index in */
  size_t first_no_uv_area_triangle;  /* that mesh; both SIZE_MAX when there is none */
  size_t clamped_uvs;                /* lightmap UVs (vertices; scene bakes: page UVs) at most 0.001 outside
                                        [0, 1], clamped onto it (beyond 0.001 they are refused) */
  /* Since 0.15: seam stitching (hemilight_bake_options.stitch_seams). */
  size_t seam_texels;                /* texels set by seam stitching (0 without it) */
  double stitch_seconds;             /* finding and stitching the seams, wall time, every output */
} hemilight_bake_stats;

/* As hemilight_cache_stats_init, for bake statistics. */
HEMILIGHT_API void hemilight_bake_stats_init_sized(hemilight_bake_stats* stats, size_t struct_size);
static inline void hemilight_bake_stats_init(hemilight_bake_stats* stats) {
  hemilight_bake_stats_init_sized(stats, sizeof *stats);
}

/* Bakes the irradiance lightmap (RGB float E = integral of L cos(theta) d omega) of the meshes:
 * exact UV coverage per texel, a sample at the centroid of the covered part offset along the
 * normal, hemicubes through the irradiance cache, `bounces` passes, dilation around the charts
 * (include/hemilight/bake.hpp and docs/bake.md). Texel (x, y) is at irradiance_rgb[3 (y width + x)],
 * its centre at uv ((x + 0.5) / width, (y + 0.5) / height): v grows with the row. Deterministic:
 * the same input gives bitwise the same output for any thread_count.
 * irradiance_rgb: at least 3 width height floats (irradiance_capacity, in floats).
 * valid: NULL, or at least width height bytes (valid_capacity): 1 where the texel was sampled
 *   and its samples were valid (not inside geometry), 0 for dilated or invalid texels.
 * stats may be NULL. Write the result with hemilight_exr_save_rgb.
 * Degenerate input is not refused: triangles without 3D area are skipped, UVs at most 0.001
 * outside [0, 1] clamped, triangles with 3D area but no UV area occlude without texels (unless
 * options->strict); the statistics count each.
 * Errors (nothing written): INVALID_ARGUMENT for NULL meshes (with mesh_count > 0), mesh_count 0,
 * NULL options/irradiance_rgb, capacities too small, options->ao NULL with ao_distance > 0,
 * options or struct_size (options, stats) out
 * of range (the message names the field), NULL arrays with nonzero counts, NaN/Inf positions,
 * normals or UVs, positions beyond 1e18 in magnitude, UVs more than 0.001 outside [0, 1], indices
 * out of range, with options->strict a triangle with 3D area but zero UV area ("meshes[1]:
 * triangle 0 (indices[0..2]) has zero area ..."), invalid materials, no texel covered, an
 * environment map with a bad size or a value negative, non-finite or above 1e30 (named by index),
 * a result that overflows float; OUT_OF_MEMORY over 2^31 - 1 vertices or triangles; CANCELLED when
 * progress returned 0.
 * Cost: see hemilight_cache_irradiance, once per bounce. */
HEMILIGHT_API hemilight_status hemilight_bake_lightmap(const hemilight_bake_mesh* meshes, size_t mesh_count,
                                                       const hemilight_bake_options* options, float* irradiance_rgb,
                                                       size_t irradiance_capacity, uint8_t* valid, size_t valid_capacity,
                                                       hemilight_bake_stats* stats);

/* hemilight_bake_lightmap plus the directional lightmaps, each optional (NULL = not wanted; a
 * NULL buffer's capacity is ignored). Asking for either makes the last bounce (and the first, with
 * indirect_only) integrate directionally: hemicubes of that pass cost a little more (HL2: about
 * 20% more for the whole one-bounce bake, docs/bake.md).
 * sh_l1_rgb: NULL, or at least 12 width height floats (sh_l1_capacity): four RGB images one after
 *   another, coefficient k of texel (x, y) at sh_l1_rgb[3 (k width height + y width + x)]. The L1
 *   spherical harmonics of the incoming radiance, WORLD space, c_k = integral over the texel's upper
 *   hemisphere of L Y_k d omega with Y_0 = 0.282095, (Y_1, Y_2, Y_3) = 0.488603 (y, z, x): a uniform
 *   sky L over a plane of normal n gives (sqrt(pi) L, (sqrt(3 pi)/2) L (n_y, n_z, n_x)).
 *   Irradiance for a normal d: max(0, (sqrt(pi)/2) c_0 + sqrt(pi/3) (c_3 d_x + c_1 d_y + c_2 d_z)).
 * hl2_rgb: NULL, or at least 9 width height floats (hl2_capacity): three RGB images one after another
 *   (same indexing), the irradiance through the Half-Life 2 basis vectors (-1/sqrt6, 1/sqrt2,
 *   1/sqrt3), (-1/sqrt6, -1/sqrt2, 1/sqrt3), (sqrt(2/3), 0, 1/sqrt3) of each texel's LIGHTMAP
 *   TANGENT FRAME (t, b, n): t = dP/du of the texel's triangle projected onto the tangent plane of
 *   the shading normal n and normalised; b = +-(n x t) with the sign that makes b . dP/dv >= 0
 *   (u, v: lightmap UVs). From the irradiance on the cone of HL2 directions kept per cache record as
 *   a Fourier series in azimuth (order 3): exact for light within 35.26 degrees of the normal and
 *   for a uniform sky (every value pi L (1 + 1/sqrt3) / 2); 1.7% RMS for a grazing side light
 *   (docs/bake.md).
 * Both kinds are dilated like the irradiance. Errors as hemilight_bake_lightmap, and
 * INVALID_ARGUMENT when a capacity is too small (the message names it); nothing is written then. */
HEMILIGHT_API hemilight_status hemilight_bake_lightmap_directional(const hemilight_bake_mesh* meshes, size_t mesh_count,
                                                                   const hemilight_bake_options* options,
                                                                   float* irradiance_rgb, size_t irradiance_capacity,
                                                                   uint8_t* valid, size_t valid_capacity, float* sh_l1_rgb,
                                                                   size_t sh_l1_capacity, float* hl2_rgb,
                                                                   size_t hl2_capacity, hemilight_bake_stats* stats);
/* ---- cube maps -----------------------------------------------------------------------------------
 * Float RGB cube maps: six faces in OpenGL order (+X, -X, +Y, -Y, +Z, -Z), face-major, each
 * size x size texels, rows along the GL t coordinate, columns along s, RGB interleaved
 * (6 x size x size x 3 floats). Face sizes are 1..6688. A mip chain is its levels one after
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
 * Errors: INVALID_ARGUMENT for size outside [1, 6688], face outside [0, 5], x or y outside
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
 * direction or lod, size outside [1, 6688]. */
HEMILIGHT_API hemilight_status hemilight_cubemap_fixup_lookup(const float direction[3], int size, float lod,
                                                              float out_direction[3]);

/* Filters an RGB cube map with the normalised cosine-power lobe of specular power p > 0: each
 * output texel (direction from `fixup`) is sum L W / sum W, W = exact texel solid angle x
 * max(0, cos)^p, over the lobe's extent (cutoff 1e-4), reading a coarser mip of the input where
 * the lobe spans many texels (max relative error ~0.3% against brute force on a sky with a sun,
 * docs/cubemap.md).
 * Uses all cores; deterministic. output holds 6 x output_size^2 x 3 floats and must not overlap
 * input. Errors: INVALID_ARGUMENT for NULL pointers, sizes outside [1, 6688], p not finite and
 * > 0, an unknown fixup, or NaN/Inf or values beyond +-1e30 in input (output untouched);
 * OUT_OF_MEMORY. */
HEMILIGHT_API hemilight_status hemilight_cubemap_filter_cosine_power(const float* input, int input_size,
                                                                     float specular_power,
                                                                     hemilight_edge_fixup fixup, int output_size,
                                                                     float* output);

/* Irradiance E(n) = integral of L max(0, n.w) dw per output texel (a uniform map of radiance L
 * gives pi L). use_sh = 0: the cosine-lobe filter (quadrature over the input mip of 16 x 16);
 * use_sh = 1: the 9-coefficient SH fast path (exact for radiance in SH bands 0-2, otherwise SH
 * truncation error). Errors as hemilight_cubemap_filter_cosine_power, and use_sh not 0 or 1. */
HEMILIGHT_API hemilight_status hemilight_cubemap_filter_irradiance(const float* input, int input_size,
                                                                   hemilight_edge_fixup fixup, int output_size,
                                                                   int use_sh, float* output);

/* Number of floats and levels of an RGB mip chain whose top level has size `size` (levels down to
 * 1 x 1). Either output may be NULL. Errors: INVALID_ARGUMENT for size outside [1, 6688]. */
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
 * along `direction` (need not be unit: any finite nonzero vector, 1e-45 or 1e38 long alike) at an explicit lod (clamped to [0, level_count - 1],
 * trilinear between levels), bilinear per face or seamless. apply_fixup = 1 first transforms the
 * direction with hemilight_cubemap_fixup_lookup(direction, size, lod) (lod < 0 is read as the
 * fixed-size form and samples level 0): use it for STRETCH-filtered maps. Errors:
 * INVALID_ARGUMENT for NULL pointers, size outside [1, 6688], level_count outside
 * [1, levels of size], NaN/Inf direction or lod, a zero direction, an unknown sampling,
 * apply_fixup not 0 or 1, a sample that is not finite (a chain holding NaN, Inf or values near the
 * float limit). */
HEMILIGHT_API hemilight_status hemilight_cubemap_sample(const float* chain, int size, int level_count,
                                                        const float direction[3], float lod,
                                                        hemilight_cube_sampling sampling, int apply_fixup,
                                                        float rgb[3]);

/* ---- scene bakes: lightmap pages, occluder-only meshes, per-texel materials ----------------------
 * hemilight_bake_scene bakes many meshes into several lightmap pages at once (include/hemilight/
 * bake.hpp, bake_scene; docs/bake.md, "Pages and occluders"). All pages go through the same
 * passes, so light bounces between meshes of different pages; dilation stays inside each page. */

/* Where mesh i of a scene bake goes (placements[i] for meshes[i]). */
typedef struct hemilight_bake_placement {
  int page;           /* index into the pages, or -1: occluder only (blocks hemicubes and shadow rays,
                         gets no texels, lightmap_uvs may be NULL; hemicubes see it with
                         hemilight_bake_scene_desc::occluder_radiance) */
  float uv_scale[2];  /* page UV = lightmap_uv * uv_scale + uv_offset (per component, in float):
                         Unity's lightmapScaleOffset (x, y, z, w) is scale (x, y), offset (z, w).
                         Finite; every page UV must lie in [0, 1]. */
  float uv_offset[2];
} hemilight_bake_placement;

/* One lightmap page: its size, optional per-texel materials (inputs) and its outputs (written only
 * when the whole bake succeeds). Texel (x, y) of every image is at index (y width + x) times its
 * channel count, row 0 first, as for hemilight_bake_lightmap. */
typedef struct hemilight_bake_page {
  int width, height;            /* texels, each 1..8192 */
  const float* albedo_rgb;      /* NULL, or 3 width height floats in [0, 1]: per-texel albedo used for the
                                   bounces instead of the owner triangle's */
  const float* emission_rgb;    /* NULL, or 3 width height floats in [0, 1e30]: per-texel emitted radiance
                                   instead of the triangle's (the first pass then sees it through a
                                   bilinear radiance texture) */
  float* irradiance_rgb;        /* required: the irradiance, at least 3 width height floats */
  size_t irradiance_capacity;   /* floats at irradiance_rgb */
  uint8_t* valid;               /* NULL, or width height bytes: as hemilight_bake_lightmap's valid */
  size_t valid_capacity;
  float* sh_l1_rgb;             /* NULL, or 12 width height floats: as hemilight_bake_lightmap_directional */
  size_t sh_l1_capacity;
  float* hl2_rgb;               /* NULL, or 9 width height floats: as hemilight_bake_lightmap_directional */
  size_t hl2_capacity;
  float* shadow_mask_rgba;      /* 4 width height floats when options->shadow_mask_lights names a light, else
                                   ignored (options->shadow_mask_rgba is not used by scene bakes) */
  size_t shadow_mask_capacity;
} hemilight_bake_page;

/* What hemicubes see of occluder-only meshes (hemilight_bake_scene_desc::occluder_radiance). */
#define HEMILIGHT_OCCLUDER_EMISSION 0                 /* their emission only: they reflect nothing */
#define HEMILIGHT_OCCLUDER_EMISSION_PLUS_MEAN_BOUNCE 1 /* + albedo x the previous pass's mean irradiance / pi */

/* A scene to bake; fill with hemilight_bake_scene_desc_init, then set the arrays. */
typedef struct hemilight_bake_scene_desc {
  size_t struct_size;                          /* set by hemilight_bake_scene_desc_init ("Structs that grow") */
  const hemilight_bake_mesh* meshes;           /* mesh_count meshes (as for hemilight_bake_lightmap) */
  size_t mesh_count;
  const hemilight_bake_placement* placements;  /* mesh_count placements, one per mesh */
  const hemilight_bake_page* pages;            /* page_count pages; their output buffers are written */
  size_t page_count;
  int occluder_radiance;                       /* HEMILIGHT_OCCLUDER_* (default HEMILIGHT_OCCLUDER_EMISSION) */
  int reserved0;                               /* padding, not read (the earlier layout's tail padding) */
  /* Since 0.15: see-through triangles ("opacity" above; default NULL, NULL, 0: every triangle
   * opaque, also for a program built against an older header). Read during the call only. */
  const hemilight_mesh_opacity* mesh_opacity;  /* NULL, or mesh_count entries: mesh_opacity[i] for meshes[i] (occluder-only
                                                  meshes too) */
  const hemilight_alpha_texture* alpha_textures; /* alpha_texture_count textures, the ones hemilight_opacity::alpha_texture
                                                    indexes (NULL when the count is 0) */
  size_t alpha_texture_count;
  /* Since 0.15. Where each page's ambient occlusion goes when options->ao_distance > 0 (ignored
   * otherwise): ao[p] is NULL (page p's AO not written) or width x height floats of page p, one
   * per texel, rows as its irradiance (hemilight_bake_options.ao_distance says what they hold);
   * ao_capacity[p] is the floats available at ao[p] (at least width x height). Both arrays hold
   * page_count entries and are read during the call only (default NULL). With
   * options->ao_distance > 0, ao or ao_capacity NULL, or a capacity too small, is INVALID_ARGUMENT
   * naming scene->ao[p] or scene->ao_capacity[p]. */
  float* const* ao;
  const size_t* ao_capacity;
} hemilight_bake_scene_desc;

/* As hemilight_cache_options_init_sized, for scene descriptions (all NULL and 0, emission-only
 * occluders, every triangle opaque). */
HEMILIGHT_API void hemilight_bake_scene_desc_init_sized(hemilight_bake_scene_desc* scene, size_t struct_size);
static inline void hemilight_bake_scene_desc_init(hemilight_bake_scene_desc* scene) {
  hemilight_bake_scene_desc_init_sized(scene, sizeof *scene);
}

/* Bakes every page of a scene in one bake (hemilight_bake_lightmap's pipeline over all pages).
 * options: as for hemilight_bake_lightmap, except that width and height are ignored (the pages
 * give the sizes), the shadow mask goes to each page's shadow_mask_rgba and the ambient occlusion
 * to scene->ao. The directional maps are computed when any page asks for them and written to the
 * pages that do. stats (may be NULL):
 * the whole bake. One page holding every mesh with scale (1, 1) and offset (0, 0) gives bitwise
 * what hemilight_bake_lightmap gives.
 * Errors (nothing written; the message names the function and the mesh, page or placement by
 * index, and the index within it): INVALID_ARGUMENT for NULL scene/options, a bad struct_size,
 * mesh_count or page_count 0, NULL meshes/placements/pages, an unknown occluder_radiance, a page
 * size out of range, a NULL irradiance_rgb or a capacity too small, with options->ao_distance > 0
 * a NULL scene->ao or scene->ao_capacity or an AO capacity too small, an albedo or emission value
 * out of range ("scene->pages[1].albedo_rgb[37] = 1.5"), a placement's page out of range or
 * non-finite scale/offset, a page UV more than 0.001 outside [0, 1] ("meshes[2].lightmap_uvs[9]
 * (vertex 4, v) = 0.9 maps to 1.3 in page 1"), with options->strict a triangle with no area in
 * its page (without: counted, as hemilight_bake_lightmap does), everything hemilight_bake_lightmap
 * rejects in the meshes and options, a bad opacity (as hemilight_scene_with_opacity refuses it,
 * named in the scene's terms: "scene->mesh_opacity[2].opacities[5].alpha_cutoff = 1.5 is outside
 * [0, 1]", "scene->mesh_opacity[0].texcoords[7] (vertex 3, v) = nan", "scene->alpha_textures[1]:
 * width x height = 0 x 4 is invalid"; checked before anything is allocated for them), no texel
 * sampled in any page, a result that overflows float;
 * OUT_OF_MEMORY, CANCELLED as there, and OUT_OF_MEMORY when the pages' atlas (the widest page x
 * the sum of the heights and two guard rows between pages) passes 2^28 texels (checked before it
 * is allocated).
 * Cost: as hemilight_bake_lightmap over the sum of the pages' texels; see-through triangles as
 * "opacity" above says, and 8 bytes per vertex for the texcoords when a texture is read. */
HEMILIGHT_API hemilight_status hemilight_bake_scene(const hemilight_bake_scene_desc* scene, const hemilight_bake_options* options,
                                                    hemilight_bake_stats* stats);

/* ---- sharded scene bakes: jobs anywhere, then merges --------------------------------------------
 * Since 0.15. hemilight_bake_scene split into shards (include/hemilight/shards.hpp; docs/capi.md,
 * "Sharded bakes"): jobs that run in any process or on any machine, and the merges that join
 * them. A bake of B = options->bounces bounces with S shards is B passes; pass k (1-based) is S
 * jobs and one merge:
 *   job (shard i of S, pass k):  hemilight_bake_scene_shard(scene, options, i, S, k, state_k-1)   -> shard_k,i
 *   merge (pass k < B):          hemilight_merge_bake_pass(scene, options, k, shards_k, S, shards_1, state_k-1) -> state_k
 *   finish (pass B):             hemilight_finish_sharded_bake(scene, options, shards_B, S, shards_1, state_B-1, stats)
 * (state_0 is NULL; shards_1 are pass 1's S results, which carry the lights and the ambient
 * occlusion to the merges). The finish writes the pages' outputs as hemilight_bake_scene does;
 * hemilight_bake_scene_sharded runs it all in one process. Every call is given the same scene and
 * options and recomputes the bake's set-up (geometry, atlas, samples) from them; nothing else
 * passes between calls but the shards and states, which hemilight_bake_shard_get and
 * hemilight_bake_pass_state_get turn into plain numbers and arrays, and the _create functions
 * back into handles, so that a program can ship them between machines. Each carries the bake's
 * key, a 64-bit hash of the scene and of every option but thread_count and progress (not
 * cryptographic: it catches mistakes); the merges refuse a shard or state of another bake, pass
 * or shard count, and a shard missing or given twice.
 * Determinism: a shard's values depend on the scene, the options, S, i and k only (not on
 * thread_count nor on the process that runs the job), so the result is bitwise the same however
 * the jobs are spread. With S = 1 it is bitwise hemilight_bake_scene's; with S > 1 and the
 * irradiance cache each shard places its own records (shard i holds the samples that come i-th in
 * a Morton order over the scene's bounds), so the result differs from hemilight_bake_scene's
 * within the cache's error; without the cache (options->use_cache = 0) it is bitwise
 * hemilight_bake_scene's for every S.
 * The scene: every call checks scene and options exactly as hemilight_bake_scene does, the pages'
 * output buffers and scene->ao included, so that one description serves every call. Jobs and
 * merges never read nor write those buffers, but which pages have sh_l1_rgb or hl2_rgb decides
 * whether the bake computes the directional maps (part of the key), and a shadow mask needs the
 * pages' shadow_mask_rgba: give every call the same description (a job's process may point the
 * buffers at scratch memory of the right capacity). Handles are immutable after creation and may
 * be used from any thread. */

/* Since 0.15. One job's result (C++ bake_shard_result): per sample of its shard, in the bake's
 * sample order, channel_count floats. Opaque. */
typedef struct hemilight_bake_shard hemilight_bake_shard;
/* Since 0.15. The state between two passes (C++ bake_pass_state): the radiance the next pass
 * renders, which samples are valid, and per-pass statistics. Opaque. */
typedef struct hemilight_bake_pass_state hemilight_bake_pass_state;

/* Since 0.15. Releases a shard or a state (NULL does nothing). Handles made from them stay valid:
 * nothing refers to a shard or state after the call that read it returns. */
HEMILIGHT_API void hemilight_bake_shard_release(hemilight_bake_shard* shard);
HEMILIGHT_API void hemilight_bake_pass_state_release(hemilight_bake_pass_state* state);

/* Since 0.15. Runs job `shard` (0-based) of `shard_count` of pass `pass` (1-based, in
 * [1, options->bounces]) of the sharded bake of `scene` and returns its result in a new handle
 * *out (release it with hemilight_bake_shard_release). previous: the state that
 * hemilight_merge_bake_pass made after pass - 1; NULL for pass 1, required after. Nothing is
 * written to the pages (see above); options->progress sees the job's fraction.
 * Errors (nothing written to *out): INVALID_ARGUMENT for NULL scene, options or out, everything
 * hemilight_bake_scene refuses in scene and options (its messages, named after this function),
 * shard_count not in [1, 4096], shard not in [0, shard_count), pass not in [1, options->bounces],
 * previous NULL for pass > 1 or given for pass 1, a previous state of another bake ("made by
 * another bake": another scene or options), of another pass, shard count or atlas size;
 * OUT_OF_MEMORY and CANCELLED as hemilight_bake_scene.
 * Cost: the bake's set-up (coverage of every page: O(texels)), then about 1 / shard_count of the
 * pass's hemicubes (and in pass 1 of the lights' shadow rays); the result holds 4 to 68
 * floats per sample of the shard (hemilight_bake_shard_info.channel_count). */
HEMILIGHT_API hemilight_status hemilight_bake_scene_shard(const hemilight_bake_scene_desc* scene, const hemilight_bake_options* options,
                                                          int32_t shard, int32_t shard_count, int32_t pass,
                                                          const hemilight_bake_pass_state* previous, hemilight_bake_shard** out);

/* Since 0.15. Merges pass `pass` (in [1, options->bounces - 1]) of the sharded bake of `scene`:
 * the shards' values joined, the lights added, samples inside geometry filled, and the radiance
 * texture of pass + 1 made; *out receives the new state (release it with
 * hemilight_bake_pass_state_release). shards: the shard_count results of the pass, in any order
 * (shard_count is the bake's S); first_pass: the shard_count results of pass 1 (their lights and
 * AO), ignored (may be NULL or the same array) when pass = 1; previous: the state after pass - 1
 * (NULL for pass 1). Nothing is written to the pages.
 * Errors (nothing written to *out): INVALID_ARGUMENT for NULL scene, options, shards or out, a
 * NULL element ("hemilight_merge_bake_pass: shards[2] is NULL"), first_pass NULL when pass > 1,
 * shard_count not in [1, 4096], everything hemilight_bake_scene refuses, pass out of range, a
 * shard of another bake ("shards[0] (shard 0 of pass 1) was baked from another scene or options"),
 * of another pass or shard count, a shard given twice ("shards[1] is shard 0 again"), a shard whose
 * sample or channel counts differ from this bake's, previous as hemilight_bake_scene_shard checks
 * it; OUT_OF_MEMORY.
 * Cost: the bake's set-up, a copy of the shards' values, O(atlas texels) and the dilation of the
 * radiance texture; no hemicube. The state holds 4 floats per atlas texel. */
HEMILIGHT_API hemilight_status hemilight_merge_bake_pass(const hemilight_bake_scene_desc* scene, const hemilight_bake_options* options,
                                                         int32_t pass, const hemilight_bake_shard* const* shards, size_t shard_count,
                                                         const hemilight_bake_shard* const* first_pass,
                                                         const hemilight_bake_pass_state* previous, hemilight_bake_pass_state** out);

/* Since 0.15. Merges the last pass (pass = options->bounces) of the sharded bake of `scene` and
 * writes every page's outputs (irradiance, valid, directional maps, shadow mask, scene->ao)
 * exactly as hemilight_bake_scene writes them, only when everything succeeded. shards: the
 * shard_count results of the last pass, in any order; first_pass: those of pass 1, ignored (may
 * be NULL) when options->bounces = 1; previous: the state after pass bounces - 1 (NULL when
 * bounces = 1). stats (may be NULL): the whole bake's counts (hemicubes and records summed over
 * every job of every pass); seconds is this call's wall time.
 * Errors (nothing written): as hemilight_merge_bake_pass ("hemilight_finish_sharded_bake: ..."),
 * a result that overflows float, a bad stats->struct_size.
 * Cost: as hemilight_merge_bake_pass, plus the outputs' seam stitching and dilation. */
HEMILIGHT_API hemilight_status hemilight_finish_sharded_bake(const hemilight_bake_scene_desc* scene, const hemilight_bake_options* options,
                                                             const hemilight_bake_shard* const* shards, size_t shard_count,
                                                             const hemilight_bake_shard* const* first_pass,
                                                             const hemilight_bake_pass_state* previous, hemilight_bake_stats* stats);

/* Since 0.15. The sharded bake of `scene` in one process: every job and merge above in order,
 * with the set-up made once. Writes the outputs and stats as hemilight_bake_scene does; the same
 * bits as running the jobs anywhere, and with shard_count 1 (or options->use_cache 0) bitwise
 * hemilight_bake_scene's. options->progress sees the whole bake's fraction.
 * Errors (nothing written): as hemilight_bake_scene, and INVALID_ARGUMENT for shard_count not in
 * [1, 4096].
 * Cost: hemilight_bake_scene's, plus the records the shards cannot share across their borders
 * (with the cache), and the shards' values (4 to 68 floats per sample) kept between
 * passes. */
HEMILIGHT_API hemilight_status hemilight_bake_scene_sharded(const hemilight_bake_scene_desc* scene, const hemilight_bake_options* options,
                                                            int32_t shard_count, hemilight_bake_stats* stats);

/* Since 0.15. A shard's numbers ("Structs that grow"; fill with hemilight_bake_shard_info_init
 * before hemilight_bake_shard_get or hemilight_bake_shard_create). */
typedef struct hemilight_bake_shard_info {
  size_t struct_size;     /* set by hemilight_bake_shard_info_init */
  uint64_t key;           /* the bake's key */
  int32_t pass;           /* 1-based */
  int32_t shard;          /* in [0, shard_count) */
  int32_t shard_count;    /* in [1, 4096] */
  int32_t reserved0;      /* padding: set to 0 by _init and hemilight_bake_shard_get; its value is never used */
  size_t sample_count;    /* samples of the shard */
  size_t channel_count;   /* floats per sample (hemilight_bake_shard_channel_name names each) */
  size_t hemicubes;       /* hemicubes the job rendered */
  size_t records;         /* irradiance cache records the job placed */
  size_t invalid_samples; /* samples the job found inside geometry */
  double seconds;         /* the job's wall time, set-up included */
  double direct_seconds;  /* of which the lights (pass 1) */
} hemilight_bake_shard_info;

/* As hemilight_cache_options_init_sized, for shard information (every field 0). */
HEMILIGHT_API void hemilight_bake_shard_info_init_sized(hemilight_bake_shard_info* info, size_t struct_size);
static inline void hemilight_bake_shard_info_init(hemilight_bake_shard_info* info) {
  hemilight_bake_shard_info_init_sized(info, sizeof *info);
}

/* Since 0.15. Reads a shard: its numbers into *info (within info->struct_size) and, unless values
 * is NULL (the numbers only), its sample_count x channel_count floats, sample-major (sample s,
 * channel c at values[s channel_count + c]), into values. values_capacity: floats available at
 * values. Errors (nothing written): INVALID_ARGUMENT for NULL shard or info, a bad
 * info->struct_size, values_capacity below sample_count x channel_count with values given.
 * Cost: O(sample_count x channel_count). */
HEMILIGHT_API hemilight_status hemilight_bake_shard_get(const hemilight_bake_shard* shard, hemilight_bake_shard_info* info, float* values,
                                                        size_t values_capacity);

/* Since 0.15. The name of channel `channel` of a shard ("E.R", "E.G", "E.B", "invalid", then as
 * the pass computes them "sh0.R" ..., "cone0.R" ..., "ao", "direct.E.R" ...; shards.hpp lists
 * them), valid while the shard lives; NULL for a NULL shard or a channel >= channel_count (the
 * last error is not changed). Cost: O(1). */
HEMILIGHT_API const char* hemilight_bake_shard_channel_name(const hemilight_bake_shard* shard, size_t channel);

/* Since 0.15. A shard from its numbers, channel names and values (as hemilight_bake_shard_get and
 * hemilight_bake_shard_channel_name gave them, e.g. on another machine), copied into a new handle
 * *out (release it with hemilight_bake_shard_release). info->reserved0 is not read.
 * channel_names: info->channel_count strings; values: value_count = info->sample_count x
 * info->channel_count floats, sample-major. Only the sizes and ranges are checked here; the merges
 * check that the shard belongs to their bake (key, pass, shard count, sample count, channels).
 * Errors (nothing written to *out): INVALID_ARGUMENT for NULL info or out, a bad
 * info->struct_size, info->shard_count not in [1, 4096], info->shard not in [0, shard_count),
 * info->pass not in [1, 64], channel_names NULL with a channel count or a NULL name
 * ("channel_names[3] is NULL"), value_count not sample_count x channel_count, values NULL with
 * value_count > 0, a value not finite ("values[37] (sample 9, channel E.G) = nan"), seconds or
 * direct_seconds negative or not finite; OUT_OF_MEMORY. Cost: O(value_count). */
HEMILIGHT_API hemilight_status hemilight_bake_shard_create(const hemilight_bake_shard_info* info, const char* const* channel_names,
                                                           const float* values, size_t value_count, hemilight_bake_shard** out);

/* Since 0.15. A state's numbers ("Structs that grow"; fill with hemilight_bake_pass_state_info_init
 * before hemilight_bake_pass_state_get or hemilight_bake_pass_state_create). */
typedef struct hemilight_bake_pass_state_info {
  size_t struct_size;   /* set by hemilight_bake_pass_state_info_init */
  uint64_t key;         /* the bake's key */
  int32_t pass;         /* the pass it follows (1-based, < options->bounces) */
  int32_t shard_count;  /* in [1, 4096] */
  int32_t width;        /* the pages' atlas: the widest page x the sum of the heights and two */
  int32_t height;       /* guard rows between pages */
  size_t pass_count;    /* passes with statistics so far (= pass) */
} hemilight_bake_pass_state_info;

/* As hemilight_cache_options_init_sized, for state information (every field 0). */
HEMILIGHT_API void hemilight_bake_pass_state_info_init_sized(hemilight_bake_pass_state_info* info, size_t struct_size);
static inline void hemilight_bake_pass_state_info_init(hemilight_bake_pass_state_info* info) {
  hemilight_bake_pass_state_info_init_sized(info, sizeof *info);
}

/* Since 0.15. Reads a state: its numbers into *info (within info->struct_size); unless
 * radiance_rgba is NULL, its atlas into radiance_rgba (width x height RGBA floats, rows as the
 * pages' images: RGB the radiance pass + 1 renders, A 1 where a sample lies that every pass so far
 * found outside geometry, else 0; radiance_capacity: floats available there); and per pass so far
 * (pass_count entries, pass_capacity available in each array given; each array may be NULL) the
 * hemicubes, cache records and invalid samples summed over the pass's shards, and the sum of its
 * jobs' wall times in seconds. Errors (nothing written): INVALID_ARGUMENT for NULL state or info, a
 * bad info->struct_size, radiance_capacity below 4 x width x height with radiance_rgba given,
 * pass_capacity below pass_count with a statistics array given. Cost: O(width x height). */
HEMILIGHT_API hemilight_status hemilight_bake_pass_state_get(const hemilight_bake_pass_state* state, hemilight_bake_pass_state_info* info,
                                                             float* radiance_rgba, size_t radiance_capacity, size_t* pass_hemicubes,
                                                             size_t* pass_records, size_t* pass_invalid_samples, double* pass_seconds,
                                                             size_t pass_capacity);

/* Since 0.15. A state from its numbers and arrays (as hemilight_bake_pass_state_get gave them),
 * copied into a new handle *out (release it with hemilight_bake_pass_state_release).
 * radiance_rgba: count = 4 x info->width x info->height floats; the statistics arrays:
 * info->pass_count entries each, or NULL (zeros: the finish's statistics then count nothing for
 * those passes). Only sizes and ranges are checked here; the jobs and merges check that the state
 * belongs to their bake (key, pass, shard count, atlas size, pass_count).
 * Errors (nothing written to *out): INVALID_ARGUMENT for NULL info, radiance_rgba or out, a bad
 * info->struct_size, info->pass not in [1, 63], info->shard_count not in [1, 4096], info->width or
 * height below 1 or more than 2^28 texels in all, info->pass_count above 64, count not
 * 4 x width x height, an RGB value negative or not finite, an A value not exactly 0 or 1
 * ("radiance_rgba[23] (texel 5: x 5, y 0, A) = 0.500000; it must be 0 or 1"), a pass_seconds entry
 * negative or not finite; OUT_OF_MEMORY. Cost: O(width x height). */
HEMILIGHT_API hemilight_status hemilight_bake_pass_state_create(const hemilight_bake_pass_state_info* info, const float* radiance_rgba,
                                                                size_t count, const size_t* pass_hemicubes, const size_t* pass_records,
                                                                const size_t* pass_invalid_samples, const double* pass_seconds,
                                                                hemilight_bake_pass_state** out);

/* Irradiance methods of hemilight_cubemap_irradiance (measured error against a brute-force cosine
 * integral, and time, on a sky with a sun: docs/cubemap.md). */
typedef enum hemilight_irradiance_method {
  HEMILIGHT_IRRADIANCE_FILTER = 0, /* the cosine-lobe filter over the input mip of input_size: no
                                      truncation, only quadrature error (0.6% max at 16, 0.14% at 32) */
  HEMILIGHT_IRRADIANCE_SH9,        /* SH bands 0-2 (9 coefficients): exact for radiance in bands
                                      0-2; 17% max error on a sky with a sun */
  HEMILIGHT_IRRADIANCE_SH25        /* SH bands 0-4 (25 coefficients, A_3 = 0, A_4 = -pi/24): what
                                      cmft computes; 10% max error on a sky with a sun */
} hemilight_irradiance_method;

/* Options of hemilight_cubemap_irradiance; fill with hemilight_cubemap_irradiance_options_init
 * (see "Structs that grow" at the top). */
typedef struct hemilight_cubemap_irradiance_options {
  size_t struct_size;                 /* sizeof as the caller was built: set by the _init function */
  hemilight_irradiance_method method; /* default HEMILIGHT_IRRADIANCE_FILTER: the most accurate for
                                         its time at every setting measured (docs/cubemap.md) */
  int input_size;                     /* FILTER: size of the input mip it reads, 1..6688, clamped to
                                         the input's size (default 16: 0.6% max error, ~4 ms CPU for a
                                         32^2 output of a 256^2 sky); ignored by the SH methods */
  int thread_count;                   /* 0 = all cores (default 0); results do not depend on it */
} hemilight_cubemap_irradiance_options;

/* As hemilight_cache_options_init_sized, for cube-map irradiance options. */
HEMILIGHT_API void hemilight_cubemap_irradiance_options_init_sized(hemilight_cubemap_irradiance_options* options,
                                                                   size_t struct_size);
/* Fills options with the defaults above (inline: records the caller's sizeof). NULL is ignored. */
static inline void hemilight_cubemap_irradiance_options_init(hemilight_cubemap_irradiance_options* options) {
  hemilight_cubemap_irradiance_options_init_sized(options, sizeof *options);
}

/* Irradiance E(n) = integral of L max(0, n.w) dw per output texel of an RGB cube map (a uniform map
 * of radiance L gives pi L), by options->method (options may be NULL: the defaults). Deterministic:
 * bitwise the same for any thread count. output holds 6 x output_size^2 x 3 floats and must not
 * overlap input. Errors (output untouched): INVALID_ARGUMENT for NULL input/output, sizes outside
 * [1, 6688], an unknown fixup or method, input_size outside [1, 6688] (FILTER), a struct_size not
 * set by the _init function or newer than the library, NaN/Inf or values beyond +-1e30 in input;
 * OUT_OF_MEMORY. Cost: FILTER 6 output_size^2 x 3 input_size^2 multiply-adds; SH9 / SH25 about 30
 * / 100 flops per input texel plus 40 / 100 per output texel. */
HEMILIGHT_API hemilight_status hemilight_cubemap_irradiance(const float* input, int input_size,
                                                            hemilight_edge_fixup fixup, int output_size,
                                                            const hemilight_cubemap_irradiance_options* options,
                                                            float* output);
/* ---- lightmap UVs -------------------------------------------------------------------------------
 * hemilight_generate_lightmap_uvs gives a mesh lightmap UVs (include/hemilight/unwrap.hpp,
 * docs/unwrap.md): vertices at the same position welded, charts grown by normal deviation (planar
 * ones projected, curved ones flattened by least-squares conformal maps), packed with padding
 * into square pages at a texel density or into one page. The result is new vertex arrays: each
 * output vertex copies an input vertex (vertex_source: copy its position, normal, other UVs) and has
 * its UV in its page; triangles keep their order. Deterministic: the same bytes for any thread
 * count. */

/* Unwrap options; fill with hemilight_unwrap_options_init (see "Structs that grow" at the top). */
typedef struct hemilight_unwrap_options {
  size_t struct_size;     /* set by hemilight_unwrap_options_init */
  float texels_per_unit;  /* texel density (texels per scene unit), finite, >= 0; 0: the largest density at
                             which every chart fits one page (default 0) */
  int page_size;          /* width and height of each page in texels, 16..8192 (default 1024) */
  int padding;            /* empty texels between charts and at the border, 0..64 and below page_size / 4
                             (default 2) */
  float max_chart_angle;  /* degrees, 1..89: most a triangle's normal may deviate from its chart's mean
                             normal (default 60) */
  int max_pages;          /* with texels_per_unit > 0: most pages the charts may need, 1..4096 (default 64) */
  int thread_count;       /* 0 = all cores (default 0); results do not depend on it */
} hemilight_unwrap_options;

/* As hemilight_cache_options_init_sized, for unwrap options. */
HEMILIGHT_API void hemilight_unwrap_options_init_sized(hemilight_unwrap_options* options, size_t struct_size);
static inline void hemilight_unwrap_options_init(hemilight_unwrap_options* options) {
  hemilight_unwrap_options_init_sized(options, sizeof *options);
}

typedef struct hemilight_unwrap_stats {
  size_t struct_size;           /* set by hemilight_unwrap_stats_init */
  size_t charts;                /* charts packed */
  size_t planar_charts;         /* of them, projected onto their plane */
  size_t degenerate_triangles;  /* triangles without area: in no chart, their UVs without area */
  int pages;                    /* pages used (1 with texels_per_unit = 0) */
  float texels_per_unit;        /* the density of every chart (the one found, for a target size) */
  double uv_area_fraction;      /* the triangles' UV area over the pages' area */
  double stretch_l2;            /* Sander et al.'s L2 stretch (>= 1; 1 for an isometry) */
  double stretch_linf;          /* Sander et al.'s L-infinity stretch */
  double seam_texels;           /* UV length in texels, both sides, of the edges between charts */
  double seconds;               /* wall time */
} hemilight_unwrap_stats;

/* As hemilight_cache_stats_init, for unwrap statistics. */
HEMILIGHT_API void hemilight_unwrap_stats_init_sized(hemilight_unwrap_stats* stats, size_t struct_size);
static inline void hemilight_unwrap_stats_init(hemilight_unwrap_stats* stats) {
  hemilight_unwrap_stats_init_sized(stats, sizeof *stats);
}

/* Lightmap UVs for a mesh (positions: 3 * vertex_count floats, finite; indices: 3 * triangle_count,
 * each < vertex_count; front faces counter-clockwise). options may be NULL (the defaults).
 * Outputs (written only on success):
 *   vertex_source   vertex_capacity uint32: per output vertex, the input vertex it copies
 *   uvs             2 * vertex_capacity floats: per output vertex, (u, v) in [0, 1] of its page
 *                   (texel (x, y) of a page of size S has its centre at ((x + 0.5) / S, (y + 0.5) / S))
 *   out_indices     3 * triangle_count uint32, into the output vertices
 *   triangle_page   NULL, or triangle_count uint32: each triangle's page
 *   *vertex_count_out  the number of output vertices, at most 3 * triangle_count
 * vertex_capacity must be at least 3 * triangle_count (the bound, checked before any work).
 * triangle_count 0: *vertex_count_out = 0, nothing else written (the arrays may be NULL).
 * stats may be NULL.
 * Errors (nothing written): INVALID_ARGUMENT for NULL positions/indices with nonzero counts, NULL
 * vertex_source/uvs/out_indices/vertex_count_out, vertex_capacity below 3 * triangle_count,
 * NaN/Inf or beyond 1e18 positions, indices out of range, options or a struct_size out of range
 * (the message names the field), charts that do not fit one page even at one texel each
 * (texels_per_unit 0), charts that need more than max_pages pages, a triangle larger than a page at
 * texels_per_unit; OUT_OF_MEMORY for more than (2^31 - 1) / 3 triangles.
 * Cost: O(V + T log T) plus a sparse factorisation per curved chart (about a second per million
 * triangles on two cores; docs/unwrap.md); memory up to about 350 bytes per triangle at its peak. */
HEMILIGHT_API hemilight_status hemilight_generate_lightmap_uvs(const float* positions, size_t vertex_count, const uint32_t* indices,
                                                               size_t triangle_count, const hemilight_unwrap_options* options,
                                                               uint32_t* vertex_source, float* uvs, size_t vertex_capacity,
                                                               uint32_t* out_indices, uint32_t* triangle_page, size_t* vertex_count_out,
                                                               hemilight_unwrap_stats* stats);

/* ---- memory kept between calls -----------------------------------------------------------------
 * Tables that depend only on a resolution (hemicube weights, integrator weights, SH9 and HL2 cone
 * weights, cube-map face tables) are built on first use and kept in one process-wide cache of the
 * least recently used ones within a byte budget (default 256 MiB: every table of two hemicube
 * resolutions up to 512). A table in use by a sampler, a call or another thread is never freed
 * under it. Besides the cache, each thread that called hemilight_sample_irradiance with N <= 512
 * keeps one context for its last N: 45 bytes per hemicube texel (3 N^2) of scratch plus a
 * reference to that N's integrator weights (69 bytes per texel), 342 N^2 bytes in all (86 MiB at
 * N = 512, 1.3 MiB at N = 64). docs/reliability.md ("Memory") gives every entry's peak. */

/* Sets the table cache's budget in bytes (0: keep no table between calls) and frees least
 * recently used tables until the kept ones fit. Never fails; thread-safe. Cost: O(tables kept). */
HEMILIGHT_API void hemilight_set_table_budget(size_t bytes);

/* The table cache's budget in bytes (268435456 unless hemilight_set_table_budget changed it). */
HEMILIGHT_API size_t hemilight_table_budget(void);

/* Bytes of the tables the cache keeps now (<= the budget; tables held only by live samplers or
 * running calls are not counted). Thread-safe. */
HEMILIGHT_API size_t hemilight_table_bytes(void);

/* Frees what hemilight keeps between calls: every table in the cache (the budget is unchanged)
 * and the per-thread context of hemilight_sample_irradiance of every thread not inside a call at
 * that moment (a thread inside a call keeps its context until a later release or its exit), then
 * (with glibc) returns the freed heap memory to the system (malloc_trim).
 * Tables used by live samplers (hemilight_sampler_create) stay until those are released. Later
 * calls rebuild what they need, with bitwise the same results. Never fails; thread-safe.
 * Cost: O(tables kept + threads). */
HEMILIGHT_API void hemilight_release_tables(void);

#ifdef __cplusplus
}
#endif

#endif /* HEMILIGHT_H */
