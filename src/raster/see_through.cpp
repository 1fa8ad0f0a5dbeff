// See-through triangles in a hemicube (raster.hpp, "See-through surfaces"): the alpha-tested and
// translucent triangles of scene::see_through_triangles(), drawn after the opaque ones by a
// per-texel ray test of their own, as a chain of steps:
//   draw_see_through   -> each triangle's faces and texel boxes (see_through_faces)
//                      -> per texel: inside (watertight triple products), depth (the opaque
//                         paths' plane formula), near plane, depth test, alpha test
//                      -> alpha-tested: depth and id written like an opaque fragment;
//                         translucent: a fragment kept for the composite;
//   keep_cutouts / restore_cutouts (exact edge coverage: a texel an alpha-tested triangle wins
//                         keeps what its centre sees);
//   composite_translucent -> per texel, the translucent layers in front of what it sees, far to
//                         near: L = transmittance L + the layer's own radiance.
// The depth and the texel ids are the opaque paths' (internal.hpp), so the resolve, the UV pass
// and seen_triangle() treat an alpha-tested fragment as any other.
#include "internal.hpp"

#include <algorithm>
#include <cfloat>
#include <cmath>

namespace hemilight {

using namespace raster_detail;

namespace {

// The edges of a triangle for the inside test: per edge a -> b, the normal a x b of the plane
// through the point and the edge, in double, computed from the endpoints in a canonical order
// (lexicographic) and negated when reversed. Two triangles sharing an edge get exactly opposite
// normals; on a face, n . D for the texel centre D = a + u c + v r (the face's axes, components
// 0 or +-1) is A + v C + u B with A, B, C exact components of n, evaluated row by row in the same
// operations for every triangle: exactly opposite values for the two, the base of the watertight
// inside test.
struct edge_planes {
  glm::dvec3 normal[3];
  bool canonical[3];

  explicit edge_planes(const glm::vec3 (&l)[3]) noexcept {
    const auto less = [](const glm::vec3& p, const glm::vec3& q) {
      if (p.x != q.x) return p.x < q.x;
      if (p.y != q.y) return p.y < q.y;
      return p.z < q.z;
    };
    for (int k = 0; k < 3; ++k) {
      const glm::vec3& a = l[k];
      const glm::vec3& b = l[(k + 1) % 3];
      canonical[k] = !less(b, a);
      const glm::dvec3 c = glm::cross(glm::dvec3(canonical[k] ? a : b), glm::dvec3(canonical[k] ? b : a));
      normal[k] = canonical[k] ? c : -c;
    }
  }
};

// The edge functions of one face: s_k(u, v) = a[k] + v c[k] + u b[k] (n_k . D, see above).
struct face_edges {
  double a[3], b[3], c[3];
  bool canonical[3];
  face_edges(int face, const edge_planes& e) noexcept {
    for (int k = 0; k < 3; ++k) {
      const glm::dvec3& n = e.normal[k];
      // to_clip's permutation and signs: (c . n, r . n, a . n).
      switch (face) {
        case 0: b[k] = n.x, c[k] = n.y, a[k] = n.z; break;
        case 1: b[k] = n.y, c[k] = n.z, a[k] = n.x; break;
        case 2: b[k] = -n.y, c[k] = n.z, a[k] = -n.x; break;
        case 3: b[k] = -n.x, c[k] = n.z, a[k] = n.y; break;
        default: b[k] = n.x, c[k] = n.z, a[k] = -n.y; break;
      }
      canonical[k] = e.canonical[k];
    }
  }
  // Whether the centre ray passes through the triangle (either side), from the row's values
  // row[k] = a[k] + v c[k]. A ray exactly on an edge belongs to the triangle that runs along the
  // edge in its canonical direction: of two triangles sharing an edge (the same winding seen from
  // the point), exactly one.
  bool inside(const double (&row)[3], double u) const noexcept {
    bool pos = false, neg = false;
    for (int k = 0; k < 3; ++k) {
      const double s = row[k] + u * b[k];
      if (s > 0.0 || (s == 0.0 && canonical[k])) pos = true;
      if (s < 0.0 || (s == 0.0 && !canonical[k])) neg = true;
    }
    return pos != neg;
  }
  // The columns [x0, x1] of a row that may pass the test with the sign `sign` (the triangle's
  // orientation seen from the point: the sign of its plane offset), widened by a column for the
  // rounding of the bounds; false when none can.
  bool span(const double (&row)[3], double sign, double first, double step, int& x0, int& x1) const noexcept {
    double lo = -1e300, hi = 1e300;
    for (int k = 0; k < 3; ++k) {
      const double sb = sign * b[k], sr = sign * row[k];
      if (sb > 0.0) lo = std::max(lo, -sr / sb);
      else if (sb < 0.0) hi = std::min(hi, -sr / sb);
      else if (sr < 0.0) return false;  // the whole row is outside this edge
    }
    if (lo > hi) {  // empty, or a single point within the rounding of the bounds
      if (lo - hi > 1e-9 * (std::fabs(lo) + std::fabs(hi))) return false;
      hi = lo;
    }
    const double c0 = std::floor((lo - first) / step) - 1.0, c1 = std::ceil((hi - first) / step) + 1.0;
    x0 = static_cast<int>(std::max(c0, double(x0)));
    x1 = static_cast<int>(std::min(c1, double(x1)));
    return x0 <= x1;
  }
};

// The texels of face `face` (columns x0..x1, rows y0..y1) whose centre rays may meet the triangle
// with clip-space vertices c (to_clip of its local vertices): its projection's box where all three
// lie in front of the near plane, the whole face otherwise. False when it cannot reach the face.
bool see_through_box(int face, const clip_vertex (&c)[3], int n, double step, double first, float near, int& x0, int& x1,
                     int& y0, int& y1) noexcept {
  const int rows = face == 0 ? n : n / 2;
  // Wholly behind the near plane, or wholly beyond one side of the face's frustum.
  const auto all = [&](auto outside) { return outside(c[0]) && outside(c[1]) && outside(c[2]); };
  if (all([&](const clip_vertex& v) { return v.w < near; })) return false;
  if (all([](const clip_vertex& v) { return v.u > v.w; }) || all([](const clip_vertex& v) { return v.u < -v.w; }) ||
      all([](const clip_vertex& v) { return v.v > v.w; }) ||
      all([&](const clip_vertex& v) { return face == 0 ? v.v < -v.w : v.v < 0.0f; }))
    return false;
  x0 = 0, x1 = n - 1, y0 = 0, y1 = rows - 1;
  if (!(c[0].w >= near && c[1].w >= near && c[2].w >= near)) return true;
  double umin = DBL_MAX, umax = -DBL_MAX, vmin = DBL_MAX, vmax = -DBL_MAX;
  for (const clip_vertex& v : c) {
    const double u = double(v.u) / double(v.w), w = double(v.v) / double(v.w);
    umin = std::min(umin, u), umax = std::max(umax, u), vmin = std::min(vmin, w), vmax = std::max(vmax, w);
  }
  // Texel centres: u = first + x step; v = first + y step (top) or (y + 1/2) step (sides). One
  // texel of margin covers the rounding of the projection.
  const double v_first = face == 0 ? first : 0.5 * step;
  const auto lo = [&](double a, double f, int count) {
    return static_cast<int>(std::max(0.0, std::min(double(count - 1), std::floor((a - f) / step) - 1.0)));
  };
  const auto hi = [&](double a, double f, int count) {
    return static_cast<int>(std::max(0.0, std::min(double(count - 1), std::ceil((a - f) / step) + 1.0)));
  };
  if (umax < first - step || vmax < v_first - step || umin > 1.0 + step || vmin > 1.0 + step) return false;
  x0 = lo(umin, first, n), x1 = hi(umax, first, n);
  y0 = lo(vmin, v_first, rows), y1 = hi(vmax, v_first, rows);
  return true;
}

}  // namespace

void raster_detail::rasterizer_impl::draw_see_through(const glm::vec3& position, const frame& basis) {
  translucent_.clear();
  translucent_draws_.clear();
  cutouts_.clear();
  const std::vector<scene::triangle>& tris = scene_->see_through_triangles();
  // Alpha-tested triangles first: the translucent ones are tested against the final depths.
  for (int pass = 0; pass < 2; ++pass)
    for (const scene::triangle& tri : tris) {
      const bool translucent = scene_->triangle_material(tri.index).opacity == surface_opacity::translucent;
      if (translucent != (pass == 1)) continue;
      draw_see_through_triangle(tri, translucent, position, basis);
    }
}

void raster_detail::rasterizer_impl::draw_see_through_triangle(const scene::triangle& tri, bool translucent,
                                                               const glm::vec3& position, const frame& basis) {
  ++stats_.see_through_tested;
  const glm::vec3 local[3] = {basis.to_local(tri.v0 - position), basis.to_local(tri.v1 - position),
                              basis.to_local(tri.v2 - position)};
  // The record as draw_triangle makes it: the same plane, so the same depths as an opaque
  // triangle in that plane.
  draw_record rec;
  rec.normal = basis.to_local(glm::cross(tri.v1 - tri.v0, tri.v2 - tri.v0));
  rec.v0 = local[0];
  rec.plane = glm::dot(rec.normal, rec.v0);
  if (!(rec.plane != 0.0f) || !std::isfinite(rec.plane)) return;  // seen edge-on
  rec.index = tri.index;
  const float nn = glm::dot(rec.normal, rec.normal);
  const glm::vec3 le1 = local[1] - local[0], le2 = local[2] - local[0];
  // Barycentrics of a local point q: b1 = grad_b1 . (q - v0), b2 = grad_b2 . (q - v0) (the UV pass's).
  const glm::vec3 grad_b1 = glm::cross(le2, rec.normal) / nn, grad_b2 = glm::cross(rec.normal, le1) / nn;
  const bool back = rec.plane > 0.0f && (front_keys_[tri.index] & 1u);
  const float far_limit = 1.0f / near_;  // 1/w of the near plane
  const edge_planes edges(local);
  // The triangle's orientation seen from the point (det(v0, v1, v2): the sign of every edge
  // function on the rays that meet it in front).
  const double orientation = glm::dot(glm::dvec3(local[0]), glm::cross(glm::dvec3(local[1]), glm::dvec3(local[2])));
  if (!(orientation != 0.0)) return;
  std::uint32_t draw = 0;
  for (int f = 0; f < 5; ++f) {
    int x0, x1, y0, y1;
    const clip_vertex c[3] = {to_clip(f, local[0]), to_clip(f, local[1]), to_clip(f, local[2])};
    if (!see_through_box(f, c, n_, texel_step_, first_centre_, near_, x0, x1, y0, y1)) continue;
    // Hidden on this face behind what is drawn (the occlusion culling's tiles, when it ran): a
    // conservative test, so no texel changes.
    if (tiles_ready_ && triangle_hidden(f, c)) {
      ++stats_.see_through_occluded;
      continue;
    }
    if (edge_) draw = 0;  // one draw per (triangle, face), as the opaque paths number them
    face_setup fs;
    fs.prepare(f, texel_step_, first_centre_, rec);
    const std::size_t offset = hemicube_face_offset(n_, static_cast<hemicube_face>(f));
    const face_edges fe(f, edges);
    const double sign = orientation > 0.0 ? 1.0 : -1.0;
    const double v_first = f == 0 ? first_centre_ : 0.5 * texel_step_;
    for (int y = y0; y <= y1; ++y) {
      const double v = v_first + texel_step_ * y;
      const double row[3] = {fe.a[0] + v * fe.c[0], fe.a[1] + v * fe.c[1], fe.a[2] + v * fe.c[2]};
      int xa = x0, xb = x1;
      if (!fe.span(row, sign, first_centre_, texel_step_, xa, xb)) continue;
      const auto zrow = static_cast<float>(fs.z00 + fs.dzdy * y);
      for (int x = xa; x <= xb; ++x) {
        const std::size_t i = offset + static_cast<std::size_t>(y) * static_cast<std::size_t>(n_) + static_cast<std::size_t>(x);
        ++stats_.see_through_fragments;
        const float z = zrow + fs.dzdx * static_cast<float>(x);
        // In front of the point, behind the near plane's distance, nearer than what is there
        // (an opaque fragment at the same depth wins), and the centre ray inside.
        if (!(z > 0.0f && z <= far_limit && z > depth_[i])) continue;
        if (!fe.inside(row, first_centre_ + texel_step_ * x)) continue;
        const glm::vec3& d = directions_[i];
        const glm::vec3 q = (lengths_[i] / z) * d - rec.v0;
        if (translucent) {
          if (translucent_draws_.empty() || translucent_draws_.back().index != tri.index)
            translucent_draws_.push_back({rec.v0, grad_b1, grad_b2, tri.index, !back});
          translucent_.push_back({static_cast<std::uint32_t>(i), z, static_cast<std::uint32_t>(translucent_draws_.size() - 1)});
          continue;
        }
        if (!scene_->alpha_present(tri.index, glm::dot(grad_b1, q), glm::dot(grad_b2, q))) continue;
        if (draw == 0) {
          draw = commit_draw(rec.plane, tri, &rec, basis);
          if (back) {  // black, without the back-face flag (bind's see_through_back_key_)
            const auto number = static_cast<std::uint32_t>(draw_keys_.size() - 1);
            draw_keys_.back() = see_through_back_key_;
            draw = key_bits_ ? number << key_bits_ | see_through_back_key_ : number;
          }
        }
        depth_[i] = z;
        ids_[i] = draw;
        cutouts_.push_back(static_cast<std::uint32_t>(i));
      }
    }
  }
}

void raster_detail::rasterizer_impl::keep_cutouts(const hemicube_buffer& out) {
  // The texels an alpha-tested fragment still holds after every draw, with what the resolve gave them.
  kept_cutouts_.clear();
  const std::size_t count = out.texel_count();
  std::sort(cutouts_.begin(), cutouts_.end());
  cutouts_.erase(std::unique(cutouts_.begin(), cutouts_.end()), cutouts_.end());
  for (const std::uint32_t i : cutouts_) {
    const std::uint32_t draw = ids_[i] >> key_bits_;
    const std::uint32_t tri = draw_triangles_[draw];
    if (tri == no_triangle || scene_->triangle_material(tri).opacity != surface_opacity::alpha_tested) continue;
    kept_cutouts_.push_back({i, out.radiance[i], out.radiance[count + i], out.radiance[2 * count + i], out.distance[i], out.flags[i]});
  }
}

void raster_detail::rasterizer_impl::restore_cutouts(hemicube_buffer& out) const {
  const std::size_t count = out.texel_count();
  for (const kept_texel& k : kept_cutouts_) {
    out.radiance[k.texel] = k.r;
    out.radiance[count + k.texel] = k.g;
    out.radiance[2 * count + k.texel] = k.b;
    out.distance[k.texel] = k.distance;
    out.flags[k.texel] = k.flags;
  }
}

void raster_detail::rasterizer_impl::composite_translucent(hemicube_buffer& out, const radiance_texture* texture) {
  if (translucent_.empty()) return;
  stats_.translucent_fragments = translucent_.size();
  // Per texel, far to near (1/w ascending); equal depths in drawing order, the later drawn nearer.
  // Grouped by texel with a counting sort (O(fragments + texels)), then each texel's few layers
  // sorted by insertion.
  const std::size_t texels = out.texel_count();
  layer_start_.assign(texels + 1, 0u);
  for (const translucent_fragment& f : translucent_) ++layer_start_[f.texel + 1];
  for (std::size_t i = 0; i < texels; ++i) layer_start_[i + 1] += layer_start_[i];
  layers_.resize(translucent_.size());
  {
    std::vector<std::uint32_t>& next = layer_fill_;
    next.assign(layer_start_.begin(), layer_start_.end() - 1);
    for (const translucent_fragment& f : translucent_) layers_[next[f.texel]++] = f;  // drawing order kept
  }
  const auto farther_first = [](const translucent_fragment& a, const translucent_fragment& b) {
    return a.z < b.z || (a.z == b.z && a.draw < b.draw);
  };
  for (std::size_t i = 0; i < texels; ++i) {
    const std::uint32_t b = layer_start_[i], e = layer_start_[i + 1];
    for (std::uint32_t k = b + 1; k < e; ++k)
      for (std::uint32_t j = k; j > b && farther_first(layers_[j], layers_[j - 1]); --j) std::swap(layers_[j], layers_[j - 1]);
  }
  translucent_.swap(layers_);
  const std::size_t count = texels;
  const bool textured = texture && scene_->has_lightmap_uvs();
  const std::vector<glm::vec2>& uvs = scene_->lightmap_uvs();
  const std::vector<std::uint32_t>& indices = scene_->indices();
  for (const translucent_fragment& f : translucent_) {
    const translucent_draw& rec = translucent_draws_[f.draw];
    const material& m = scene_->triangle_material(rec.index);
    glm::vec3 own(0.0f);
    if (rec.front) {
      if (textured) {
        const glm::vec3 q = (lengths_[f.texel] / f.z) * directions_[f.texel] - rec.v0;
        const float b1 = glm::dot(rec.grad_b1, q), b2 = glm::dot(rec.grad_b2, q);
        const std::uint32_t* v = indices.data() + 3 * static_cast<std::size_t>(rec.index);
        const glm::vec2& uv0 = uvs[v[0]];
        own = texture->sample(uv0 + b1 * (uvs[v[1]] - uv0) + b2 * (uvs[v[2]] - uv0));
      } else {
        own = m.emission;
      }
    }
    float* l[3] = {&out.radiance[f.texel], &out.radiance[count + f.texel], &out.radiance[2 * count + f.texel]};
    for (int c = 0; c < 3; ++c) *l[c] = m.transmittance[c] * *l[c] + own[c];
  }
}

}  // namespace hemilight
