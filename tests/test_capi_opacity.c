/* C99 test of the C ABI's opacity (hemilight.h, "opacity"): hemilight_opacity's defaults, the
 * scene description's opacity fields, hemilight_scene_with_opacity and hemilight_bake_scene's
 * mesh_opacity: every refusal (named, nothing written), and what see-through triangles do.
 *
 * Run without arguments: what the scene alone decides (an alpha-tested triangle whose alpha is
 * below its cutoff and that reads no texture is left out of the scene: it must behave as absent;
 * the same triangle opaque must not), the handles' sky, environment, lights and edge coverage
 * kept.
 * Run with --drawn (CTest: capi_opacity_drawn_c99, label "opacity"): what needs the rasterizer and
 * the ray queries to draw and test see-through triangles: a card whose alpha texture is half open
 * casts a shadow only under its closed half, to the texel (shadow rays) and as an opaque half card
 * does (hemicubes); a translucent pane tints the light through it by its transmittance.
 * References: a hard sun straight down gives a floor its irradiance exactly where nothing covers
 * it and 0 where an opaque card does (sky 0, black occluder, one bounce); a uniform sky of
 * radiance L gives pi L; through a pane of transmittance T the same light gives T times it.
 * Prints failing checks and a closing "N passed, N failed" line. */
#include "capi_check.h"

#include <math.h>
#include <stdio.h>
#include <string.h>

#define W 8
static float page_out[3 * W * W];
static uint8_t page_valid[W * W];

static void fill_sentinel(void) {
  int i;
  for (i = 0; i < 3 * W * W; ++i) page_out[i] = -7.0f;
  memset(page_valid, 9, sizeof page_valid);
}
static int untouched(void) {
  int i;
  for (i = 0; i < 3 * W * W; ++i)
    if (page_out[i] != -7.0f) return 0;
  for (i = 0; i < W * W; ++i)
    if (page_valid[i] != 9) return 0;
  return 1;
}

/* A unit floor quad (x in [0, 1], z in [-1, 0]) facing up, its lightmap UVs u = x, v = -z; and a
 * card 0.5 above it, facing down, over x in [-0.5, 1.5], z in [-1.5, 0.5] (an occluder only),
 * whose texcoords run u = (x + 0.5) / 2 across it: a texture whose right half is opaque covers
 * x >= 0.5 exactly. */
static const float floor_positions[] = {0, 0, 0, 1, 0, 0, 1, 0, -1, 0, 0, -1};
static const float floor_uvs[] = {0, 0, 1, 0, 1, 1, 0, 1};
static const float card_positions[] = {-0.5f, 0.5f, 0.5f, -0.5f, 0.5f, -1.5f, 1.5f, 0.5f, -1.5f, 1.5f, 0.5f, 0.5f};
static const float card_texcoords[] = {0, 0, 0, 1, 1, 1, 1, 0};
static const uint32_t quad_indices[] = {0, 1, 2, 0, 2, 3};
/* 8 x 1 texels: the left half transparent, the right half opaque. */
static const uint8_t half_open[8] = {0, 0, 0, 0, 255, 255, 255, 255};

typedef struct card_bake {
  hemilight_bake_mesh meshes[2];
  hemilight_bake_placement placements[2];
  hemilight_bake_page page;
  hemilight_bake_scene_desc scene;
  hemilight_mesh_opacity opacity[2];
  hemilight_alpha_texture texture;
  hemilight_light sun;
  hemilight_bake_options options;
} card_bake;

/* The floor and the card under a hard sun of irradiance 2 straight down, sky 0, one bounce; the
 * card alpha-tested by the half-open texture. */
static void make_card_bake(card_bake* b) {
  const hemilight_opacity opaque = HEMILIGHT_OPACITY_DEFAULT;
  int i;
  memset(b, 0, sizeof *b);
  b->meshes[0].positions = floor_positions;
  b->meshes[0].lightmap_uvs = floor_uvs;
  b->meshes[0].vertex_count = 4;
  b->meshes[0].indices = quad_indices;
  b->meshes[0].triangle_count = 2;
  b->meshes[0].material.albedo[0] = b->meshes[0].material.albedo[1] = b->meshes[0].material.albedo[2] = 0.5f;
  b->meshes[1] = b->meshes[0];
  b->meshes[1].positions = card_positions;
  b->meshes[1].lightmap_uvs = NULL;
  b->meshes[1].material.albedo[0] = b->meshes[1].material.albedo[1] = b->meshes[1].material.albedo[2] = 0.0f;
  for (i = 0; i < 2; ++i) b->placements[i].uv_scale[0] = b->placements[i].uv_scale[1] = 1.0f;
  b->placements[1].page = -1;
  b->page.width = b->page.height = W;
  b->page.irradiance_rgb = page_out;
  b->page.irradiance_capacity = 3 * W * W;
  b->page.valid = page_valid;
  b->page.valid_capacity = W * W;
  b->opacity[0].opacity = opaque;
  b->opacity[1].opacity = opaque;
  b->opacity[1].opacity.mode = HEMILIGHT_ALPHA_TESTED;
  b->opacity[1].opacity.alpha_texture = 0;
  b->opacity[1].texcoords = card_texcoords;
  b->texture.values = half_open;
  b->texture.width = 8;
  b->texture.height = 1;
  hemilight_bake_scene_desc_init(&b->scene);
  b->scene.meshes = b->meshes;
  b->scene.mesh_count = 2;
  b->scene.placements = b->placements;
  b->scene.pages = &b->page;
  b->scene.page_count = 1;
  b->scene.mesh_opacity = b->opacity;
  b->scene.alpha_textures = &b->texture;
  b->scene.alpha_texture_count = 1;
  hemilight_light_init(&b->sun, HEMILIGHT_LIGHT_DIRECTIONAL);
  b->sun.color[0] = b->sun.color[1] = b->sun.color[2] = 2.0f;
  hemilight_bake_options_init(&b->options);
  b->options.resolution = 16;
  b->options.lights = &b->sun;
  b->options.light_count = 1;
}

/* Every floor texel (each channel) equals `lit` in the columns where `in_light(x)` and 0
 * elsewhere; both exact (1e-6: the sun's irradiance times float transmittances). */
static int floor_is(const float lit[3], int first_lit_column, int last_lit_column) {
  int x, y, c, ok = 1;
  for (y = 0; y < W; ++y)
    for (x = 0; x < W; ++x)
      for (c = 0; c < 3; ++c) {
        const float want = x >= first_lit_column && x <= last_lit_column ? lit[c] : 0.0f;
        const float e = page_out[3 * (y * W + x) + c];
        if (!(fabs(e - want) <= 1e-6)) {
          if (ok) printf("  floor texel (%d, %d) channel %d = %g, expected %g\n", x, y, c, e, want);
          ok = 0;
        }
      }
  return ok;
}

static void test_defaults(void) {
  const hemilight_opacity d = HEMILIGHT_OPACITY_DEFAULT;
  hemilight_opacity o;
  hemilight_bake_scene_desc sd;
  memset(&o, 0x5a, sizeof o);
  hemilight_opacity_init(&o);
  hemilight_opacity_init(NULL); /* ignored */
  CHECK(memcmp(&o, &d, sizeof o) == 0);
  CHECK(d.mode == HEMILIGHT_OPAQUE && d.alpha == 1.0f && d.alpha_cutoff == 0.5f && d.alpha_texture == -1);
  CHECK(d.transmittance[0] == 0.0f && d.transmittance[1] == 0.0f && d.transmittance[2] == 0.0f);
  CHECK(HEMILIGHT_OPAQUE == 0 && HEMILIGHT_ALPHA_TESTED == 1 && HEMILIGHT_TRANSLUCENT == 2);
  memset(&sd, 0x5a, sizeof sd);
  hemilight_bake_scene_desc_init(&sd);
  CHECK(sd.struct_size == sizeof sd && sd.mesh_opacity == NULL && sd.alpha_textures == NULL && sd.alpha_texture_count == 0);
  /* The opacity fields come after every field of the earlier layout. */
  CHECK(offsetof(hemilight_bake_scene_desc, mesh_opacity) >= offsetof(hemilight_bake_scene_desc, occluder_radiance) + sizeof(int));
}

/* A point at the origin facing up under a black card one unit above it (x, z in [-1, 1], facing
 * down), sky radiance 1. */
static const float up[3] = {0, 1, 0}, origin[3] = {0, 0, 0};
static const float sky1[3] = {1, 1, 1};
static const float overhead_card[] = {-1, 1, 1, -1, 1, -1, 1, 1, -1, 1, 1, 1};
static const float overhead_half[] = {0, 1, 1, 0, 1, -1, 1, 1, -1, 1, 1, 1}; /* its x >= 0 half, opaque */
static const float overhead_texcoords[] = {0, 0, 0, 1, 1, 1, 1, 0};         /* u = (x + 1) / 2 */
static const float black[6] = {0, 0, 0, 0, 0, 0};

static float irradiance_at(const hemilight_scene* scene, const float position[3], int channel) {
  hemilight_irradiance e;
  memset(&e, 0, sizeof e);
  CHECK(hemilight_sample_irradiance(scene, position, up, 64, &e) == HEMILIGHT_OK);
  return e.irradiance[channel];
}
static float irradiance(const hemilight_scene* scene, int channel) { return irradiance_at(scene, origin, channel); }

static void test_scene_refusals(void) {
  hemilight_scene *card = NULL, *sentinel = (hemilight_scene*)&card, *out = sentinel;
  hemilight_opacity o[2];
  hemilight_alpha_texture t;
  float bad_texcoords[8];
  CHECK(hemilight_scene_create(overhead_card, 4, quad_indices, 2, black, sky1, &card) == HEMILIGHT_OK);
  hemilight_opacity_init(&o[0]);
  hemilight_opacity_init(&o[1]);
  t.values = half_open;
  t.width = 8;
  t.height = 1;
  CHECK_FAILS(hemilight_scene_with_opacity(NULL, o, NULL, NULL, 0, &out), HEMILIGHT_ERROR_INVALID_ARGUMENT,
              "hemilight_scene_with_opacity: scene is NULL");
  CHECK_FAILS(hemilight_scene_with_opacity(card, o, NULL, NULL, 0, NULL), HEMILIGHT_ERROR_INVALID_ARGUMENT,
              "hemilight_scene_with_opacity: out is NULL");
  CHECK_FAILS(hemilight_scene_with_opacity(card, NULL, NULL, NULL, 0, &out), HEMILIGHT_ERROR_INVALID_ARGUMENT,
              "hemilight_scene_with_opacity: opacities is NULL but the scene has 2 triangles");
  o[1].mode = 3;
  CHECK_FAILS(hemilight_scene_with_opacity(card, o, NULL, NULL, 0, &out), HEMILIGHT_ERROR_INVALID_ARGUMENT,
              "hemilight_scene_with_opacity: opacities[1].mode = 3 is not HEMILIGHT_OPAQUE (0), HEMILIGHT_ALPHA_TESTED (1) or "
              "HEMILIGHT_TRANSLUCENT (2)");
  o[1].mode = HEMILIGHT_ALPHA_TESTED;
  o[1].alpha_cutoff = 1.5f;
  CHECK_FAILS(hemilight_scene_with_opacity(card, o, NULL, NULL, 0, &out), HEMILIGHT_ERROR_INVALID_ARGUMENT,
              "hemilight_scene_with_opacity: opacities[1].alpha_cutoff = 1.5 is outside [0, 1]");
  o[1].alpha_cutoff = 0.5f;
  o[1].alpha = NAN;
  CHECK_FAILS(hemilight_scene_with_opacity(card, o, NULL, NULL, 0, &out), HEMILIGHT_ERROR_INVALID_ARGUMENT,
              "hemilight_scene_with_opacity: opacities[1].alpha = nan is outside [0, 1]");
  o[1].alpha = 1.0000001f; /* the float just above 1: named as such, not rounded onto the bound */
  CHECK_FAILS(hemilight_scene_with_opacity(card, o, NULL, NULL, 0, &out), HEMILIGHT_ERROR_INVALID_ARGUMENT,
              "hemilight_scene_with_opacity: opacities[1].alpha = 1.0000001 is outside [0, 1]");
  o[1].alpha = 1.0f;
  o[1].alpha_texture = 1;
  CHECK_FAILS(hemilight_scene_with_opacity(card, o, overhead_texcoords, &t, 1, &out), HEMILIGHT_ERROR_INVALID_ARGUMENT,
              "hemilight_scene_with_opacity: opacities[1].alpha_texture = 1 is not -1 or an index into alpha_textures "
              "(alpha_texture_count 1)");
  o[1].alpha_texture = -2;
  CHECK_FAILS(hemilight_scene_with_opacity(card, o, overhead_texcoords, &t, 1, &out), HEMILIGHT_ERROR_INVALID_ARGUMENT,
              "opacities[1].alpha_texture = -2 is not -1 or an index");
  o[1].alpha_texture = 0;
  CHECK_FAILS(hemilight_scene_with_opacity(card, o, NULL, &t, 1, &out), HEMILIGHT_ERROR_INVALID_ARGUMENT,
              "hemilight_scene_with_opacity: opacities[1].alpha_texture = 0 names an alpha texture but texcoords is NULL");
  memcpy(bad_texcoords, overhead_texcoords, sizeof bad_texcoords);
  bad_texcoords[7] = INFINITY;
  CHECK_FAILS(hemilight_scene_with_opacity(card, o, bad_texcoords, &t, 1, &out), HEMILIGHT_ERROR_INVALID_ARGUMENT,
              "hemilight_scene_with_opacity: texcoords[7] (vertex 3, v) = inf; it must be finite");
  CHECK_FAILS(hemilight_scene_with_opacity(card, o, overhead_texcoords, NULL, 1, &out), HEMILIGHT_ERROR_INVALID_ARGUMENT,
              "hemilight_scene_with_opacity: alpha_textures is NULL but alpha_texture_count is 1");
  t.height = 0;
  CHECK_FAILS(hemilight_scene_with_opacity(card, o, overhead_texcoords, &t, 1, &out), HEMILIGHT_ERROR_INVALID_ARGUMENT,
              "hemilight_scene_with_opacity: alpha_textures[0]: width x height = 8 x 0 is invalid: each must be in [1, 16384]");
  t.height = 1;
  t.width = 16385;
  CHECK_FAILS(hemilight_scene_with_opacity(card, o, overhead_texcoords, &t, 1, &out), HEMILIGHT_ERROR_INVALID_ARGUMENT,
              "alpha_textures[0]: width x height = 16385 x 1 is invalid");
  t.width = 8;
  t.values = NULL;
  CHECK_FAILS(hemilight_scene_with_opacity(card, o, overhead_texcoords, &t, 1, &out), HEMILIGHT_ERROR_INVALID_ARGUMENT,
              "hemilight_scene_with_opacity: alpha_textures[0].values is NULL");
  t.values = half_open;
  o[1].mode = HEMILIGHT_TRANSLUCENT;
  o[1].transmittance[2] = -0.25f;
  CHECK_FAILS(hemilight_scene_with_opacity(card, o, NULL, NULL, 0, &out), HEMILIGHT_ERROR_INVALID_ARGUMENT,
              "hemilight_scene_with_opacity: opacities[1].transmittance[2] = -0.25 is outside [0, 1]");
  CHECK(out == sentinel); /* nothing written on any failure */
  /* Fields the mode does not use are not checked: a zeroed opacity is opaque; a translucent one
   * ignores its alpha fields. */
  memset(o, 0, sizeof o);
  o[1].mode = HEMILIGHT_TRANSLUCENT;
  o[1].alpha = -3.0f;
  o[1].alpha_texture = 7;
  CHECK(hemilight_scene_with_opacity(card, o, NULL, NULL, 0, &out) == HEMILIGHT_OK);
  CHECK(out != sentinel);
  hemilight_scene_release(out);
  /* An empty scene takes NULL opacities. */
  {
    hemilight_scene *empty = NULL, *with = NULL;
    CHECK(hemilight_scene_create(NULL, 0, NULL, 0, NULL, sky1, &empty) == HEMILIGHT_OK);
    CHECK(hemilight_scene_with_opacity(empty, NULL, NULL, NULL, 0, &with) == HEMILIGHT_OK);
    hemilight_scene_release(with);
    hemilight_scene_release(empty);
  }
  hemilight_scene_release(card);
}

/* An alpha-tested card whose alpha (0.25) is below its cutoff and that reads no texture is absent:
 * the point sees the sky, pi, as with no card; the same card opaque (through the same call) hides
 * most of it; the original handle keeps its opaque card; lights, edge coverage and the environment
 * are kept. */
static void test_scene_absent_card(void) {
  hemilight_scene *card = NULL, *absent = NULL, *opaque = NULL, *empty = NULL;
  hemilight_scene *card_lit = NULL, *absent_lit = NULL, *card_edges = NULL, *opaque_edges = NULL, *card_env = NULL,
                  *absent_env = NULL;
  hemilight_opacity o[2];
  hemilight_light sun;
  const float pi = 3.14159265f;
  float e_card, e_absent, e_opaque, e_empty;
  hemilight_opacity_init(&o[0]);
  o[0].mode = HEMILIGHT_ALPHA_TESTED;
  o[0].alpha = 0.25f;
  o[0].alpha_cutoff = 0.5f;
  o[1] = o[0];
  CHECK(hemilight_scene_create(overhead_card, 4, quad_indices, 2, black, sky1, &card) == HEMILIGHT_OK);
  CHECK(hemilight_scene_create(NULL, 0, NULL, 0, NULL, sky1, &empty) == HEMILIGHT_OK);
  CHECK(hemilight_scene_with_opacity(card, o, NULL, NULL, 0, &absent) == HEMILIGHT_OK);
  hemilight_opacity_init(&o[0]);
  hemilight_opacity_init(&o[1]);
  CHECK(hemilight_scene_with_opacity(absent, o, NULL, NULL, 0, &opaque) == HEMILIGHT_OK); /* replaces the opacity */
  e_card = irradiance(card, 0);
  e_absent = irradiance(absent, 0);
  e_opaque = irradiance(opaque, 0);
  e_empty = irradiance(empty, 0);
  CHECK(fabs(e_empty - pi) < 1e-4);
  CHECK(fabs(e_absent - e_empty) <= 1e-6 * e_empty);
  CHECK(e_card < 0.6f * pi); /* a 2 x 2 card one unit above: form factor 0.55 */
  CHECK(e_opaque == e_card);
  /* Lights are kept: a sun of irradiance 2 straight down reaches the point through the absent card. */
  hemilight_light_init(&sun, HEMILIGHT_LIGHT_DIRECTIONAL);
  sun.color[0] = sun.color[1] = sun.color[2] = 2.0f;
  CHECK(hemilight_scene_with_lights(card, &sun, 1, &card_lit) == HEMILIGHT_OK);
  o[0].mode = o[1].mode = HEMILIGHT_ALPHA_TESTED;
  o[0].alpha = o[1].alpha = 0.25f;
  CHECK(hemilight_scene_with_opacity(card_lit, o, NULL, NULL, 0, &absent_lit) == HEMILIGHT_OK);
  CHECK(fabs(irradiance(card_lit, 1) - e_card) <= 1e-6 * e_card); /* the card shadows the sun */
  CHECK(fabs(irradiance(absent_lit, 1) - (e_empty + 2.0f)) <= 1e-6 * (e_empty + 2.0f));
  /* Edge coverage is kept: the opaque card with it stays so through hemilight_scene_with_opacity.
   * Seen from a point off the centre (from the origin the card's edges lie on the hemicube's face
   * edges, where both ways agree), exact coverage and point sampling differ. */
  CHECK(hemilight_scene_with_edge_coverage(card, 1, &card_edges) == HEMILIGHT_OK);
  hemilight_opacity_init(&o[0]);
  hemilight_opacity_init(&o[1]);
  CHECK(hemilight_scene_with_opacity(card_edges, o, NULL, NULL, 0, &opaque_edges) == HEMILIGHT_OK);
  {
    const float off_centre[3] = {0.3f, 0.0f, 0.1f};
    const float e_edges = irradiance_at(card_edges, off_centre, 2);
    CHECK(e_edges != irradiance_at(card, off_centre, 2));
    CHECK(irradiance_at(opaque_edges, off_centre, 2) == e_edges);
  }
  /* The environment sky is kept: a uniform map of radiance 0.5 gives pi / 2 through the absent card. */
  {
    static float faces[6 * 4 * 4 * 3];
    int i;
    for (i = 0; i < 6 * 4 * 4 * 3; ++i) faces[i] = 0.5f;
    CHECK(hemilight_scene_with_environment(card, faces, 4, &card_env) == HEMILIGHT_OK);
    o[0].mode = o[1].mode = HEMILIGHT_ALPHA_TESTED;
    o[0].alpha = o[1].alpha = 0.25f;
    CHECK(hemilight_scene_with_opacity(card_env, o, NULL, NULL, 0, &absent_env) == HEMILIGHT_OK);
    CHECK(fabs(irradiance(absent_env, 0) - 0.5f * e_empty) <= 1e-4 * e_empty);
  }
  hemilight_scene_release(card);
  hemilight_scene_release(absent);
  hemilight_scene_release(opaque);
  hemilight_scene_release(empty);
  hemilight_scene_release(card_lit);
  hemilight_scene_release(absent_lit);
  hemilight_scene_release(card_edges);
  hemilight_scene_release(opaque_edges);
  hemilight_scene_release(card_env);
  hemilight_scene_release(absent_env);
}

static void test_bake_refusals(void) {
  static card_bake b;
  hemilight_opacity per_triangle[2];
  float bad_texcoords[8];
  make_card_bake(&b);
  fill_sentinel();
  b.opacity[1].opacity.alpha_cutoff = 1.5f;
  CHECK_FAILS(hemilight_bake_scene(&b.scene, &b.options, NULL), HEMILIGHT_ERROR_INVALID_ARGUMENT,
              "hemilight_bake_scene: scene->mesh_opacity[1].opacity.alpha_cutoff = 1.5 is outside [0, 1]");
  b.opacity[1].opacity.alpha_cutoff = 0.5f;
  per_triangle[0] = per_triangle[1] = b.opacity[1].opacity;
  per_triangle[1].mode = HEMILIGHT_TRANSLUCENT;
  per_triangle[1].transmittance[1] = 2.0f;
  b.opacity[1].opacities = per_triangle;
  CHECK_FAILS(hemilight_bake_scene(&b.scene, &b.options, NULL), HEMILIGHT_ERROR_INVALID_ARGUMENT,
              "hemilight_bake_scene: scene->mesh_opacity[1].opacities[1].transmittance[1] = 2 is outside [0, 1]");
  per_triangle[1].transmittance[1] = 0.5f;
  per_triangle[0].mode = -1;
  CHECK_FAILS(hemilight_bake_scene(&b.scene, &b.options, NULL), HEMILIGHT_ERROR_INVALID_ARGUMENT,
              "hemilight_bake_scene: scene->mesh_opacity[1].opacities[0].mode = -1 is not HEMILIGHT_OPAQUE (0)");
  per_triangle[0].mode = HEMILIGHT_ALPHA_TESTED;
  per_triangle[0].alpha_texture = 1;
  CHECK_FAILS(hemilight_bake_scene(&b.scene, &b.options, NULL), HEMILIGHT_ERROR_INVALID_ARGUMENT,
              "hemilight_bake_scene: scene->mesh_opacity[1].opacities[0].alpha_texture = 1 is not -1 or an index into "
              "scene->alpha_textures (alpha_texture_count 1)");
  per_triangle[0].alpha_texture = 0;
  b.opacity[1].texcoords = NULL;
  CHECK_FAILS(hemilight_bake_scene(&b.scene, &b.options, NULL), HEMILIGHT_ERROR_INVALID_ARGUMENT,
              "hemilight_bake_scene: scene->mesh_opacity[1].opacities[0].alpha_texture = 0 names an alpha texture but "
              "scene->mesh_opacity[1].texcoords is NULL");
  memcpy(bad_texcoords, card_texcoords, sizeof bad_texcoords);
  bad_texcoords[4] = NAN;
  b.opacity[1].texcoords = bad_texcoords;
  CHECK_FAILS(hemilight_bake_scene(&b.scene, &b.options, NULL), HEMILIGHT_ERROR_INVALID_ARGUMENT,
              "hemilight_bake_scene: scene->mesh_opacity[1].texcoords[4] (vertex 2, u) = nan; it must be finite");
  b.opacity[1].texcoords = card_texcoords;
  b.opacity[1].opacities = NULL;
  b.texture.width = 0;
  CHECK_FAILS(hemilight_bake_scene(&b.scene, &b.options, NULL), HEMILIGHT_ERROR_INVALID_ARGUMENT,
              "hemilight_bake_scene: scene->alpha_textures[0]: width x height = 0 x 1 is invalid: each must be in [1, 16384]");
  b.texture.width = 8;
  b.texture.values = NULL;
  CHECK_FAILS(hemilight_bake_scene(&b.scene, &b.options, NULL), HEMILIGHT_ERROR_INVALID_ARGUMENT,
              "hemilight_bake_scene: scene->alpha_textures[0].values is NULL");
  b.texture.values = half_open;
  b.scene.alpha_textures = NULL;
  CHECK_FAILS(hemilight_bake_scene(&b.scene, &b.options, NULL), HEMILIGHT_ERROR_INVALID_ARGUMENT,
              "hemilight_bake_scene: scene->alpha_textures is NULL but alpha_texture_count is 1");
  /* A texture index without textures at all. */
  b.scene.alpha_texture_count = 0;
  CHECK_FAILS(hemilight_bake_scene(&b.scene, &b.options, NULL), HEMILIGHT_ERROR_INVALID_ARGUMENT,
              "scene->mesh_opacity[1].opacity.alpha_texture = 0 is not -1 or an index into scene->alpha_textures "
              "(alpha_texture_count 0)");
  b.scene.alpha_textures = &b.texture;
  b.scene.alpha_texture_count = 1;
  CHECK(untouched());
}

/* The bake with an alpha-tested card whose alpha is below its cutoff without a texture: absent,
 * the whole floor in the sun (2 exactly). The same card opaque: the whole floor in its shadow (0
 * exactly). A description of the layout before the opacity fields: every triangle opaque. */
static void test_bake_absent_card(void) {
  static card_bake b;
  const float sun[3] = {2.0f, 2.0f, 2.0f};
  make_card_bake(&b);
  b.opacity[1].opacity.alpha_texture = -1;
  b.opacity[1].opacity.alpha = 0.25f;
  b.opacity[1].texcoords = NULL;
  fill_sentinel();
  CHECK(hemilight_bake_scene(&b.scene, &b.options, NULL) == HEMILIGHT_OK);
  CHECK(floor_is(sun, 0, W - 1));
  /* The per-triangle array takes precedence over the mesh's opacity. */
  {
    hemilight_opacity both_opaque[2] = {HEMILIGHT_OPACITY_DEFAULT, HEMILIGHT_OPACITY_DEFAULT};
    b.opacity[1].opacities = both_opaque;
    CHECK(hemilight_bake_scene(&b.scene, &b.options, NULL) == HEMILIGHT_OK);
    CHECK(floor_is(sun, 0, -1));
    b.opacity[1].opacities = NULL;
  }
  /* Without mesh_opacity: opaque. */
  b.scene.mesh_opacity = NULL;
  CHECK(hemilight_bake_scene(&b.scene, &b.options, NULL) == HEMILIGHT_OK);
  CHECK(floor_is(sun, 0, -1));
  /* An older caller's struct_size (before mesh_opacity): the fields beyond it are not read. */
  b.scene.mesh_opacity = b.opacity;
  b.scene.struct_size = offsetof(hemilight_bake_scene_desc, mesh_opacity);
  CHECK(hemilight_bake_scene(&b.scene, &b.options, NULL) == HEMILIGHT_OK);
  CHECK(floor_is(sun, 0, -1));
  b.scene.struct_size = sizeof b.scene;
  CHECK(hemilight_bake_scene(&b.scene, &b.options, NULL) == HEMILIGHT_OK);
  CHECK(floor_is(sun, 0, W - 1));
}

/* ---- needs see-through triangles drawn (--drawn) ------------------------------------------------ */

/* The half-open card's shadow: texel columns 0..3 (x < 0.5) in the sun, 4..7 in the shadow of the
 * card's opaque half (the texture's edge at x = 0.5 is a texel edge of the floor). */
static void test_bake_half_open_card(void) {
  static card_bake b;
  const float sun[3] = {2.0f, 2.0f, 2.0f};
  make_card_bake(&b);
  fill_sentinel();
  CHECK(hemilight_bake_scene(&b.scene, &b.options, NULL) == HEMILIGHT_OK);
  CHECK(floor_is(sun, 0, 3));
  /* The texture's opaque half on the other side (texcoords mirrored): the other columns. */
  {
    static const float mirrored[] = {1, 0, 1, 1, 0, 1, 0, 0};
    b.opacity[1].texcoords = mirrored;
    CHECK(hemilight_bake_scene(&b.scene, &b.options, NULL) == HEMILIGHT_OK);
    CHECK(floor_is(sun, 4, W - 1));
  }
}

/* A translucent pane of transmittance (0.8, 0.5, 0.25) in place of the card: the sun through it
 * on the whole floor, tinted. */
static void test_bake_pane(void) {
  static card_bake b;
  const float tinted[3] = {1.6f, 1.0f, 0.5f};
  make_card_bake(&b);
  b.opacity[1].opacity.mode = HEMILIGHT_TRANSLUCENT;
  b.opacity[1].opacity.transmittance[0] = 0.8f;
  b.opacity[1].opacity.transmittance[1] = 0.5f;
  b.opacity[1].opacity.transmittance[2] = 0.25f;
  fill_sentinel();
  CHECK(hemilight_bake_scene(&b.scene, &b.options, NULL) == HEMILIGHT_OK);
  CHECK(floor_is(tinted, 0, W - 1));
}

/* Hemicubes: the overhead card with the half-open texture hides what the opaque half card hides
 * (up to texels whose centre lies on the edge: 2e-3 of pi); with alpha 0.75 >= its cutoff and no
 * texture, all of what the opaque card hides; a translucent pane between the point and an
 * emissive ceiling passes T times the ceiling's irradiance. */
static void test_scene_drawn(void) {
  hemilight_scene *card = NULL, *half = NULL, *textured = NULL, *present = NULL;
  hemilight_opacity o[2];
  hemilight_alpha_texture t;
  const float pi = 3.14159265f;
  float e_half, e_textured, e_card, e_present;
  CHECK(hemilight_scene_create(overhead_card, 4, quad_indices, 2, black, sky1, &card) == HEMILIGHT_OK);
  CHECK(hemilight_scene_create(overhead_half, 4, quad_indices, 2, black, sky1, &half) == HEMILIGHT_OK);
  hemilight_opacity_init(&o[0]);
  o[0].mode = HEMILIGHT_ALPHA_TESTED;
  o[0].alpha_texture = 0;
  o[1] = o[0];
  t.values = half_open;
  t.width = 8;
  t.height = 1;
  CHECK(hemilight_scene_with_opacity(card, o, overhead_texcoords, &t, 1, &textured) == HEMILIGHT_OK);
  e_half = irradiance(half, 0);
  e_textured = irradiance(textured, 0);
  e_card = irradiance(card, 0);
  CHECK(e_half < 0.85f * pi && e_half > e_card + 0.15f * pi); /* the half card hides about half of the card's 55% */
  CHECK(fabs(e_textured - e_half) <= 2e-3 * pi);
  o[0].alpha_texture = o[1].alpha_texture = -1;
  o[0].alpha = o[1].alpha = 0.75f;
  CHECK(hemilight_scene_with_opacity(card, o, NULL, NULL, 0, &present) == HEMILIGHT_OK);
  e_present = irradiance(present, 0);
  CHECK(fabs(e_present - e_card) <= 1e-6 * pi);
  {
    /* An emissive ceiling (radiance 1) two units up, facing down, x and z in [-1, 1]; the pane one
     * unit up, x and z in [-1, 1] (it covers every direction to the ceiling); sky 0. */
    static const float positions[] = {-1, 2, 1, -1, 2, -1, 1, 2, -1, 1, 2, 1, -1, 1, 1, -1, 1, -1, 1, 1, -1, 1, 1, 1};
    static const uint32_t indices[] = {0, 1, 2, 0, 2, 3, 4, 5, 6, 4, 6, 7};
    static const float radiance[] = {1, 1, 1, 1, 1, 1, 0, 0, 0, 0, 0, 0};
    static const float sky0[3] = {0, 0, 0};
    hemilight_scene *both = NULL, *pane = NULL, *ceiling = NULL;
    hemilight_opacity p[4];
    const float transmittance[3] = {0.8f, 0.5f, 0.25f};
    int c, k;
    CHECK(hemilight_scene_create(positions, 8, indices, 4, radiance, sky0, &both) == HEMILIGHT_OK);
    CHECK(hemilight_scene_create(positions, 4, indices, 2, radiance, sky0, &ceiling) == HEMILIGHT_OK);
    for (k = 0; k < 4; ++k) {
      hemilight_opacity_init(&p[k]);
      if (k < 2) continue;
      p[k].mode = HEMILIGHT_TRANSLUCENT;
      for (c = 0; c < 3; ++c) p[k].transmittance[c] = transmittance[c];
    }
    CHECK(hemilight_scene_with_opacity(both, p, NULL, NULL, 0, &pane) == HEMILIGHT_OK);
    for (c = 0; c < 3; ++c) {
      const float open = irradiance(ceiling, c), through = irradiance(pane, c);
      CHECK(open > 0.5f);
      CHECK(fabs(through - transmittance[c] * open) <= 1e-5 * open);
    }
    hemilight_scene_release(both);
    hemilight_scene_release(pane);
    hemilight_scene_release(ceiling);
  }
  hemilight_scene_release(card);
  hemilight_scene_release(half);
  hemilight_scene_release(textured);
  hemilight_scene_release(present);
}

int main(int argc, char** argv) {
  if (argc > 1 && strcmp(argv[1], "--drawn") == 0) {
    test_bake_half_open_card();
    test_bake_pane();
    test_scene_drawn();
  } else {
    test_defaults();
    test_scene_refusals();
    test_scene_absent_card();
    test_bake_refusals();
    test_bake_absent_card();
  }
  printf("%d passed, %d failed\n", passed, failed);
  return failed == 0 ? 0 : 1;
}
