// Internal to the rasterizer (src/raster*.cpp): the fixed-point grid, the faces' clip space, the
// per-(triangle, face) depth set-up, and the rasterizer's state and drawing code
// (rasterizer_impl, which hemicube_rasterizer holds), shared by the coverage paths (rasterizer.cpp)
// and exact edge coverage (edge.cpp). Not installed.
#pragma once

#include "hemilight/raster.hpp"

#include <cstdint>
#include <memory>
#include <utility>
#include <vector>

#include <glm/glm.hpp>

namespace hemilight {

namespace raster_detail {

constexpr int sub_bits = 8;                   // sub-texel bits of the fixed-point grid
constexpr std::int64_t sub_one = 1 << sub_bits;
constexpr std::int64_t sub_half = sub_one / 2;
// Guard band: clip |u|, |v| <= 1000 w. Wide, so that big triangles crossing a face's edges are
// rarely clipped (clipping multiplies the rows to walk), narrow enough that snapped coordinates
// stay below 1001 * 2048 * 256 < 2^29 for N <= 4096 (edge-function terms below 2^60 in int64).
constexpr float guard_band = 1000.0f;
constexpr int max_clip_vertices = 3 + 5;      // each of the 5 clip planes adds at most one

// A vertex in a face's clip space: u = c.p, v = r.p, w = a.p (geometry.hpp face axes).
struct clip_vertex {
  float u, v, w;
};

// The local-frame point p seen on face f, as (c.p, r.p, a.p). Exact (sign changes, permutation).
inline clip_vertex to_clip(int face, const glm::vec3& p) noexcept {
  switch (face) {
    case 0: return {p.x, p.y, p.z};
    case 1: return {p.y, p.z, p.x};
    case 2: return {-p.y, p.z, -p.x};
    case 3: return {-p.x, p.z, p.y};
    default: return {p.x, p.z, -p.y};
  }
}

// floor(a / 2^sub_bits) and ceil(a / 2^sub_bits) for any sign.
// (Arithmetic right shift: floor for negative values too; every supported compiler does this,
// and C++20 requires it.)
inline std::int64_t floor_sub(std::int64_t a) noexcept { return a >> sub_bits; }
inline std::int64_t ceil_sub(std::int64_t a) noexcept { return -floor_sub(-a); }

// A point of a face's fixed-point grid (1/2^sub_bits texel; x: columns, y: rows).
struct fixed_point {
  std::int64_t x, y;
};

// A triangle of the fixed-point grid, counter-clockwise (positive area), as draw_fixed sets it up.
struct fixed_triangle {
  fixed_point p[3];
  double unsnapped[6];                      // x0 x1 x2 y0 y1 y2 before snapping, in p's order
  std::int64_t min_x, max_x, min_y, max_y;  // bounds of p
};

// The texels of a face whose centre lies in a box: columns x_begin..x_end, rows y_begin..y_end
// (empty when a begin exceeds its end).
struct texel_box {
  std::int64_t x_begin, x_end, y_begin, y_end;
};

/// A triangle drawn in the current hemicube, in the local frame. The clipping and big-triangle
/// paths use its geometry; a textured render keeps one per draw for the UV pass.
struct draw_record {
  glm::vec3 normal;      ///< (v1 - v0) x (v2 - v0), local frame
  float plane;           ///< normal . v0 (local; the point is the origin); < 0 for a front face
  glm::vec3 v0;          ///< first vertex, local frame
  std::uint32_t index;   ///< scene triangle (scene_desc numbering)
  glm::vec3 grad_b1;     ///< barycentric b1 = grad_b1 . (q - v0)  (only with a texture)
  glm::vec3 grad_b2;     ///< barycentric b2 = grad_b2 . (q - v0)
  bool textured;         ///< UVs + texture: radiance comes from the texture
  const std::uint32_t* vertices = nullptr;  ///< a LOD proxy's scene vertices (UVs); null: those of `index`
};
/// What the resolve pass copies to the texels of a draw: the sky, a back face, or the front of
/// a triangle with one of the scene's emissions.
// A partial fragment's triangle over its texel (exact edge coverage, edge.cpp): the unsnapped
// edge functions f0[k] + gx[k] x + gy[k] y (x, y in texel units from the texel's corner; inside
// where all are >= 0) and the edges that cut the texel (bit k of clip).
struct fragment_shape {
  double f0[3], gx[3], gy[3];
  double norm[3];  // |(gx[k], gy[k])|
  unsigned clip;
};

struct shade {
  float r, g, b;
  std::uint32_t flags;
};


// The depth plane of one (triangle, face) pair, computed when the pair first covers a texel.
struct face_setup {
  bool ready = false;
  double z00 = 0.0, dzdy = 0.0;
  float dzdx = 0.0f;

  // step = 2 / N, u0 = 1 / N - 1: the texel pitch and the first texel centre in face units
  // (hemicube_rasterizer::prepare computes them once per resolution).
  void prepare(int face, double step, double u0, const draw_record& rec) noexcept {
    if (ready) return;
    // Depth 1/w of the triangle's plane at texel centres: with the plane n.p = k and
    // p = w (a + u c + v r), 1/w = (n.a + u n.c + v n.r) / k, affine in the texel indices.
    // Evaluated per row in double, then per texel in float.
    const raster_detail::clip_vertex nm = raster_detail::to_clip(face, rec.normal);  // (n.c, n.r, n.a)
    const double inv_k = 1.0 / static_cast<double>(rec.plane);
    const double v0 = face == 0 ? u0 : 0.5 * step;  // side faces: rows start at v = 0
    dzdx = static_cast<float>(nm.u * step * inv_k);
    dzdy = nm.v * step * inv_k;
    z00 = (nm.w + nm.u * u0 + nm.v * v0) * inv_k;
    ready = true;
  }
};

struct simd_frame;  // the frame and position broadcast for the AVX2 set-up (kernels_avx2.hpp)

// The edges of a scene that exact edge coverage may find hard in some view (edge_coverage.cpp):
// mesh boundaries, material changes and creases (edges between two triangles of one material in
// different planes, hard where one faces the point and the other not). Edges inside a plane of one
// material are never hard and are left out. Built once per scene, kept with it.
struct edge_table {
  struct candidate {
    std::uint32_t triangle;  // scene::triangles() position
    std::uint32_t k;         // the edge: vertex k to vertex k + 1 (mod 3)
    std::uint32_t plane_a;   // a crease's two triangles' entries in `planes`; no_triangle: always hard
    std::uint32_t plane_b;
  };
  std::vector<candidate> candidates;
  std::vector<glm::vec4> planes;  // unit normal, offset of the creases' triangles
};

// The edge table of `s`, built on the first call (thread-safe; O(T log T)).
const edge_table& edge_table_of(const scene& s);

// Per scene triangle (scene_desc numbering), what a draw needs of it: front_key = (2 + its
// emission index) << 1 | 1 if it is one-sided (a draw reads this one compact word instead of the
// material and the emission index: two cache misses per drawn triangle on a large level), and
// position = its place in scene::triangles(), the reference order (settle_ties; no_triangle for
// triangles not drawn there).
struct triangle_keys {
  std::vector<std::uint32_t> front_key, position;
};

// The triangle keys of `s`, built on the first call (thread-safe; O(T); 8 bytes per triangle,
// shared by every rasterizer of the scene). Precondition: fewer than 2^30 distinct emissions.
const triangle_keys& triangle_keys_of(const scene& s);

// The texels where a fragment's depth equalled the depth already there (a tie, which the drawing
// order decides), with that depth: occlusion culling's front-to-back pass checks after drawing
// whether a tie still holds a texel's final depth. Ties are rare (coplanar overlapping triangles);
// past `limit` entries (twice the hemicube's texels: set by the render) only `overflow` is kept.
struct tie_log {
  std::size_t limit = 0;
  struct entry {
    const float* depth;  // the texel's depth (in the rasterizer's depth buffer)
    float z;             // the tied depth
    std::uint32_t id;    // the texel id of the fragment that tied (and lost to the earlier one)
  };
  std::vector<entry> at;
  bool overflow = false;
  void clear() noexcept {
    at.clear();
    overflow = false;
  }
  // Lanes `bits` of the group of texels at `depth` with depths `z`, all of draw `id` (a cold path).
  __attribute__((noinline, cold)) void add(const float* depth, const float* z, std::uint32_t id, unsigned bits) {
    for (; bits; bits &= bits - 1) {
      const unsigned lane = static_cast<unsigned>(__builtin_ctz(bits));
      if (at.size() == limit) {
        overflow = true;
        return;
      }
      at.push_back({depth + lane, z[lane], id});
    }
  }
};

// The state and drawing code of a hemicube_rasterizer (raster.hpp): the public class holds one
// of these and forwards to it. The hot code is member functions of this class, so nothing in
// the drawing loops goes through the public object. Cache-line aligned (heap-allocated on its
// own): the counters one thread writes share no line with another rasterizer's members.
class alignas(64) rasterizer_impl {
 public:
  static constexpr std::uint32_t no_triangle = hemicube_rasterizer::no_triangle;

  // The public functions of hemicube_rasterizer (raster.hpp has their contracts).
  void bind(std::shared_ptr<const scene> s, const raster_options& options);
  void unbind() noexcept;
  // What textured draw `rec` gives texel `texel` seen at distance t: the texture at the UV of the
  // hit point t d on its triangle (perspective-correct). The one formula of every path.
  glm::vec3 textured_texel(const draw_record& rec, std::size_t texel, float t, const radiance_texture& texture) const {
    const glm::vec3 q = t * directions_[texel] - rec.v0;
    const float b1 = glm::dot(rec.grad_b1, q), b2 = glm::dot(rec.grad_b2, q);
    const std::vector<glm::vec2>& uvs = scene_->lightmap_uvs();
    const std::uint32_t* v = rec.vertices ? rec.vertices : scene_->indices().data() + 3 * static_cast<std::size_t>(rec.index);
    const glm::vec2& uv0 = uvs[v[0]];
    return texture.sample(uv0 + b1 * (uvs[v[1]] - uv0) + b2 * (uvs[v[2]] - uv0));
  }
  // A textured render's radiance: per texel won by a textured draw, the texture at the UV of the
  // hit point t d on its triangle (perspective-correct); other texels keep their shade.
  void resolve_textured(std::size_t count, const float* distance, const std::uint32_t* ids, const radiance_texture& texture,
                        float* red, float* green, float* blue) const;
  void render(const glm::vec3& position, const frame& basis, int resolution, hemicube_buffer& out,
              const radiance_texture* texture);
  void render_coverage(const glm::vec3& position, const frame& basis, int resolution,
                       std::vector<std::uint32_t>& counts);
  std::uint32_t seen_triangle(std::size_t texel) const noexcept;
  float near_distance() const noexcept { return near_; }
  const raster_statistics& statistics() const noexcept { return stats_; }
  const std::shared_ptr<const scene>& scene_ptr() const noexcept { return scene_; }

 private:
  enum class mode { depth, count };
  void check_arguments(const char* who, const glm::vec3& position, const frame& basis, int resolution) const;
  void prepare(int resolution);
  unsigned drop_faces_between_texel_centres(const bvh_node& node, unsigned mask, const glm::vec3& position,
                                            const frame& basis, bool hard) const;
  template <mode M>
  void draw_all(const glm::vec3& position, const frame& basis);
  template <mode M>
  void draw_triangle(const scene::triangle& tri, unsigned face_mask, const glm::vec3& position, const frame& basis,
                     const std::uint32_t* vertices = nullptr);
  template <mode M>
  void raster_face(int face, const glm::vec3 (&local)[3], draw_record& rec, std::uint32_t& draw, const frame& basis,
                   const scene::triangle& tri);
  std::uint32_t commit_record(float plane, const scene::triangle& tri, const draw_record* rec, const frame& basis);
  // commit_record, out of line (commit_record is inlined into the set-up; see_through.cpp calls this).
  std::uint32_t commit_draw(float plane, const scene::triangle& tri, const draw_record* rec, const frame& basis);
  template <mode M>
  void draw_fixed(int face, const std::int64_t (&px)[3], const std::int64_t (&py)[3], face_setup& fs,
                  draw_record& rec, std::uint32_t& draw, const frame& basis, const scene::triangle& tri,
                  const double* exact = nullptr);
  bool draw_hard_texels(int face, const fixed_triangle& t, face_setup& fs, draw_record& rec, std::uint32_t& draw,
                        const frame& basis, const scene::triangle& tri);
  template <mode M, bool log>
  void draw_leaf_avx2(const scene::triangle* all, std::uint32_t first, std::uint32_t count, unsigned face_mask, const simd_frame& sf,
                      const frame& basis);
  template <mode M, bool log>  // the same, compiled for AVX-512 (leaf_avx.inl)
  void draw_leaf_avx512(const scene::triangle* all, std::uint32_t first, std::uint32_t count, unsigned face_mask,
                        const simd_frame& sf, const frame& basis);

  // Exact edge coverage (raster_options::edge_coverage; edge_coverage.cpp): its state, per view
  // and per render, in edges_; its drawing steps below.
  struct edge_fragment {
    std::uint32_t texel;  // hemicube texel index
    float z;              // the triangle's 1/w at the texel centre (the depth test's value)
    float coverage;       // the covered fraction of the texel's weight, [0, 1]
    std::uint32_t id;     // the draw's texel id (as in ids_)
    std::uint64_t mask;   // the cells of the texel's 8 x 8 grid it may touch (edge_cell_mask; 0: not made yet)
    std::uint32_t shape;  // its entry in edges_.fragment_shapes
  };
  struct edge_group {
    std::uint32_t texel;
    std::uint32_t first, count;  // its fragments in edges_.grouped
  };
  struct edge_state {
    const edge_table* table = nullptr;  // the scene's edges that may be hard (built once per scene)
    std::vector<std::int8_t> facing;    // per table->planes entry in this view: +1, -1, 0 (edge-on)
    // Hard edges: those that bound what is drawn in a view (mesh boundaries, material changes,
    // silhouettes); only texels they may cross need exact coverage. Per face row (face 0's N
    // rows, then each side face's N / 2): bit c of word c / 64 set when a hard edge may cross
    // texel c (words_per_row words a row).
    std::vector<std::uint64_t> hard_bits;
    std::vector<std::uint64_t> silhouette_bits;  // the same for silhouette edges only
    std::size_t words_per_row = 0;
    std::vector<float> whole_z;              // per hard texel: 1/w of the nearest triangle covering it whole (0 = none)
    std::vector<std::uint32_t> whole_id;     // and its texel id
    std::vector<std::uint32_t> hard_texels;  // the texels marked in hard_bits (cleared by prepare)
    std::vector<std::int32_t> hard_rows;     // per face row: lowest, highest hard column (lo > hi: none)
    unsigned hard_faces = 0;                 // faces with a hard texel
    // Per texel: the slopes wx, wy of its weight's density across it, relative to the centre's
    // (texel units; edge_make_density, once per resolution: density_n).
    std::vector<float> density;
    int density_n = 0;
    std::vector<fragment_shape> fragment_shapes;  // per fragment (edge_fragment::shape)
    std::vector<edge_fragment> fragments;
    std::vector<std::uint32_t> fragment_count;    // per texel: its fragments (0 = none)
    std::vector<edge_fragment> grouped;           // fragments by texel (groups' ranges)
    std::vector<std::uint32_t> fragment_texels;   // texels with fragments, in first-touch order
    std::vector<edge_group> groups;
  };
  void edge_prepare(std::size_t count, int resolution);
  void edge_texels(int face, const std::int64_t (&px)[3], const std::int64_t (&py)[3], const double (&exact)[6],
                   const face_setup& fs, std::uint32_t draw, bool back);
  void edge_mark_hard(const glm::vec3& position, const frame& basis);
  void edge_mark_segment(const glm::vec3& a, const glm::vec3& b, bool silhouette);
  bool edge_box_is_hard(int face, std::int64_t c0, std::int64_t c1, std::int64_t r0, std::int64_t r1) const noexcept;
  template <class Visit>
  void edge_for_hard(std::size_t row, std::int64_t c0, std::int64_t c1, Visit&& visit) const;
  double edge_hidden_part(edge_fragment* order, std::uint32_t i, double wx, double wy) const;
  void edge_make_density();
  void edge_group_fragments();
  void edge_blend(hemicube_buffer& out, const frame& basis, const radiance_texture* texture);
  // What texel `texel` gets from fragment `id` at depth z: the texture at its UV (a textured
  // draw: the resolve's formula, the same bits) or its shade's radiance.
  glm::vec3 fragment_radiance(std::uint32_t id, std::size_t texel, float z, const radiance_texture* texture) const;
  bool edge_ = false;
  edge_state edges_;

  // Occlusion culling (raster_options::diagnostics.occlusion_culling; occlusion.cpp): a node is
  // skipped on a face when its nearest possible depth is behind the least depth of every 8 x 8
  // tile its texels lie in (a conservative hierarchical depth, kept lazily per tile).
  struct node_rects {
    std::int32_t x0[5], x1[5], y0[5], y1[5];  // per face, the texels whose centres the node may cover
  };
  void occlusion_prepare();
  // The faces of `mask` on which the node (or a leaf's group) may cover a texel centre not hidden
  // by the occluders; their texel rectangles go to `rects`. Hidden on all of them: counted in
  // stats_ with its `triangles`.
  unsigned occlusion_test(const bvh_node& node, unsigned mask, const glm::vec3& position, const frame& basis,
                          node_rects& rects, std::uint32_t triangles);
  void occlusion_drawn(unsigned mask, const node_rects& rects);
  void occlusion_freeze();
  bool hidden_in_tile(int face, int tx, int ty, int x0, int x1, int y0, int y1, float nearest);
  bool rect_hidden(int face, int x0, int x1, int y0, int y1, float nearest);
  bool plane_hidden(int face, const texel_box& box, const face_setup& fs);  // a triangle's box, its plane
  bool triangle_hidden(int face, const clip_vertex (&c)[3]);  // a triangle before clipping
  bool texel_rect(int face, float u0, float u1, float v0, float v1, int& x0, int& x1, int& y0, int& y1) const;
  bool culling_ = false;  // a traversal with occlusion tests is drawing (draw_fixed tests big triangles too)
  bool tiles_ready_ = false;  // this render's tiles hold (a lower bound of) the opaque depths: see-through triangles are tested too
  template <mode M>
  void traverse(const glm::vec3& position, const frame& basis, bool cull);
  void traverse_front_to_back(const glm::vec3& position, const frame& basis);
  template <mode M>
  void draw_leaf(const bvh_node& node, unsigned mask, const glm::vec3& position, const frame& basis, const simd_frame& sf);
  void redraw_prepare();
  // A logged tie holds its texel's final depth between fragments the buffer can tell apart (other
  // shades, or other texture values in a textured render), or the log overflowed.
  bool ties_decide_order() const;
  // Each logged tie that holds its texel's final depth: the texel goes to the tied fragment the
  // reference order draws first (the lower position in scene::triangles()). Not with level of
  // detail (proxies have no position) nor after an overflow.
  void settle_ties();
  // See-through triangles (scene::see_through_triangles(); see_through.cpp): drawn after the
  // opaque ones, alpha-tested into depth_ and ids_, translucent as fragments composited over the
  // resolved buffer.
  struct translucent_fragment {
    std::uint32_t texel;
    float z;             // 1/w at the texel centre
    std::uint32_t draw;  // its entry in translucent_draws_
  };
  struct translucent_draw {
    glm::vec3 v0, grad_b1, grad_b2;  // local frame, as draw_record's
    std::uint32_t index;             // scene triangle
    bool front;                      // seen from its front (or two-sided): sends its own radiance
  };
  struct kept_texel {
    std::uint32_t texel;
    float r, g, b, distance;
    std::uint8_t flags;
  };
  void draw_see_through(const glm::vec3& position, const frame& basis);
  void draw_see_through_triangle(const scene::triangle& tri, bool translucent, const glm::vec3& position, const frame& basis);
  void keep_cutouts(const hemicube_buffer& out);
  void restore_cutouts(hemicube_buffer& out) const;
  void composite_translucent(hemicube_buffer& out, const radiance_texture* texture);
  std::uint32_t see_through_back_key_ = 0;  // the shade of a see-through triangle's back (bind)
  std::vector<translucent_fragment> translucent_;
  std::vector<translucent_fragment> layers_;   // composite_translucent's scratch: the fragments by texel
  std::vector<std::uint32_t> layer_start_, layer_fill_;  // and each texel's first, per texel + 1
  std::vector<translucent_draw> translucent_draws_;
  std::vector<std::uint32_t> cutouts_;  // texels an alpha-tested fragment won when drawn
  std::vector<kept_texel> kept_cutouts_;

  // Level of detail (raster_options::lod_texels; lod.cpp): a node spanning under lod_texels_
  // texels is drawn from its proxy.
  bool lod_draw(const bvh_node& node, std::uint32_t node_index, unsigned mask, const glm::vec3& position, const frame& basis);
  const struct lod_proxies* lod_ = nullptr;
  float lod_texels_ = 0.0f;
  bool occlusion_ = true;
  tie_log ties_;                               // the depth ties of this render's front-to-back pass
  tie_log* tie_sink_ = nullptr;                // &ties_ while that pass draws, else null (no logging)
  const float* occluders_ = nullptr;           // the depths the tiles are read from (depth_, or a frozen copy)
  std::vector<float> frozen_depth_;            // occlusion_freeze's copy
  std::vector<float> tile_depth_;              // per tile: least 1/w of its texels (0: one is empty)
  std::vector<std::uint8_t> tile_dirty_;       // per tile: tile_depth_ is stale (or never read whole)
  std::size_t tile_offset_[5] = {};            // each face's first tile
  int tiles_x_ = 0, tiles_y_[5] = {};          // tiles per row, rows of tiles per face
  std::vector<std::uint32_t> subtree_triangles_;  // per BVH node: the triangles below it (statistics)
  const std::uint32_t* front_keys_ = nullptr;   // triangle_keys_of(*scene_): front_key (bind)
  const std::uint32_t* bvh_position_ = nullptr;  // and position

  std::shared_ptr<const scene> scene_;
  float near_ = 0.0f;
  bool simd_ = true;
  bool avx2_ = false;  // simd_ and the CPU has AVX2
  bool avx512_ = false;  // avx2_, the option, and the CPU has AVX-512 F, VL, BW and DQ
  bool depth_clear_ = false;  // depth_ is all zero (the last render's resolve cleared it)
  std::shared_ptr<const cubemap> sky_;
  int n_ = 0;
  double texel_step_ = 0.0, first_centre_ = 0.0;  // 2 / N and 1 / N - 1 (face units)
  std::vector<float> depth_;           // 1/w of the nearest fragment per texel (0 = none)
  std::vector<std::uint32_t> ids_;     // draw of the nearest fragment per texel (0 = none; see key_bits_)
  std::vector<std::uint32_t>* counts_ = nullptr;
  std::vector<glm::vec3> directions_;  // unit texel-centre directions, local frame
  std::vector<float> lengths_;         // |a + u c + v r| of each texel centre
  // Draws: a triangle's first covered texel of a render gives it a draw number, which the texels
  // it wins hold in ids_ (0 = nothing hit).
  std::vector<std::uint32_t> draw_keys_;       // per draw: its entry in shades_
  std::vector<std::uint32_t> draw_triangles_;  // per draw: the scene triangle (seen_triangle)
  std::vector<draw_record> draws_;             // per draw, textured renders only: the UV pass's data
  bool textured_ = false;                      // this render samples a texture (draws_ is kept)
  const radiance_texture* texture_ = nullptr;  // that texture (textured_ renders; the tie check reads it)
  // [0] the sky, [1] a back face, [2 + e] the front of a triangle with scene emission e: built
  // once, so a draw needs no radiance of its own and equal radiances share one key.
  std::vector<shade> shades_;
  // Texel ids (ids_): draw << key_bits_ | the draw's shade key, or the draw alone when they
  // do not fit in 31 bits (key_bits_ = 0; the resolve then looks keys up in draw_keys_).
  std::uint32_t key_bits_ = 0;
  std::vector<std::uint64_t> stack_;  // the traversal's stack (reference order) or heap (front to back)
  raster_statistics stats_;
};

}  // namespace raster_detail

}  // namespace hemilight
