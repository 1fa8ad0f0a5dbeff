// bake_key (shards.hpp): a 64-bit hash of a scene bake's input and options, field by field.
#include "hemilight/cubemap.hpp"
#include "hemilight/shards.hpp"

#include "../core/hash.hpp"

#include <cstring>
#include <type_traits>

namespace hemilight {

namespace {

// Feeds bytes into a 64-bit state, eight at a time, through core_detail::mix.
class key_hasher {
 public:
  void bytes(const void* data, std::size_t n) {
    const auto* p = static_cast<const unsigned char*>(data);
    add(n);
    for (; n >= 8; n -= 8, p += 8) {
      std::uint64_t w;
      std::memcpy(&w, p, 8);
      add(w);
    }
    if (n > 0) {
      std::uint64_t w = 0;
      std::memcpy(&w, p, n);
      add(w);
    }
  }
  template <class T>
  void value(const T& v) {
    static_assert(std::is_arithmetic_v<T> || std::is_enum_v<T>, "plain values only (structs have padding)");
    std::uint64_t w = 0;
    std::memcpy(&w, &v, sizeof v);
    add(w);
  }
  void vec(const glm::vec2& v) { value(v.x), value(v.y); }
  void vec(const glm::vec3& v) { value(v.x), value(v.y), value(v.z); }
  template <class T>
  void array(const T* data, std::size_t n) {  // vectors of floats (no padding: glm::vec2/vec3, floats, integers)
    static_assert(std::is_trivially_copyable_v<T>);
    if (data)
      bytes(data, n * sizeof(T));
    else
      add(0xa11a11a11ull);  // null differs from empty
  }
  std::uint64_t result() const { return core_detail::mix(h_); }

 private:
  void add(std::uint64_t w) { h_ = core_detail::mix(h_ ^ w) + 0x632be59bd9b4e019ull; }
  std::uint64_t h_ = 0x68656d696c696768ull;
};

void hash_material(key_hasher& h, const material& m) {
  h.vec(m.emission), h.vec(m.albedo), h.value(m.two_sided), h.value(m.opacity), h.value(m.alpha), h.value(m.alpha_cutoff);
  h.value(m.alpha_texture), h.vec(m.transmittance);
}

void hash_image(key_hasher& h, const image& img) {
  h.value(img.width), h.value(img.height), h.value(img.channels);
  h.array(img.pixels.data(), img.pixels.size());
}

void hash_scene(key_hasher& h, const scene_bake_input& in) {
  const scene_desc& d = in.geometry.scene;
  h.value(d.vertex_count), h.value(d.triangle_count);
  h.array(d.positions, d.vertex_count);
  h.array(d.indices, 3 * d.triangle_count);
  h.array(d.lightmap_uvs, d.vertex_count);
  h.array(in.geometry.normals, d.vertex_count);
  h.array(d.texcoords, d.vertex_count);
  h.value(d.materials != nullptr);
  if (d.materials)
    for (std::size_t t = 0; t < d.triangle_count; ++t) hash_material(h, d.materials[t]);
  h.vec(d.sky_radiance);
  h.value(d.alpha_texture_count);
  for (std::size_t k = 0; d.alpha_textures && k < d.alpha_texture_count; ++k) {
    const alpha_texture& t = d.alpha_textures[k];
    h.value(t.width), h.value(t.height);
    h.array(t.values, t.values ? std::size_t(t.width) * std::size_t(t.height) : 0);
  }
  h.value(in.pages.size());
  for (const lightmap_page& p : in.pages) {
    h.value(p.width), h.value(p.height);
    hash_image(h, p.albedo);
    hash_image(h, p.emission);
  }
  h.value(in.meshes.size());
  for (const bake_mesh& m : in.meshes) {
    h.value(m.first_triangle), h.value(m.triangle_count), h.value(m.page);
    h.vec(m.uv_scale), h.vec(m.uv_offset);
  }
  h.value(in.occluders);
}

void hash_sampler(key_hasher& h, const sampler_options& s) {
  h.value(s.resolution), h.value(s.roll);
  const raster_options& r = s.raster;
  h.value(r.near_distance), h.value(r.edge_coverage), h.value(r.lod_texels);
  h.value(r.sky != nullptr);
  if (r.sky) {
    h.value(r.sky->level_count());
    for (const cube_image& level : r.sky->levels) {
      h.value(level.size), h.value(level.channels);
      h.array(level.pixels.data(), level.pixels.size());
    }
  }
  const integrate_options& i = s.integrate;
  h.value(i.rotation_gradient), h.value(i.translation), h.value(i.min_wall_distance), h.value(i.extrapolate_wall_depth);
  h.value(i.directional), h.value(i.double_precision), h.value(i.simd_kernels);
}

void hash_cache(key_hasher& h, const cache_options& c) {
  h.value(c.error_threshold), h.value(c.min_radius), h.value(c.max_radius), h.value(c.min_radius_spacings);
  h.value(c.use_gradients), h.value(c.weight), h.value(c.second_order), h.value(c.invalid_backface_fraction);
  const cache_expert_options& e = c.expert;
  h.value(e.limit_radius_by_gradient), h.value(e.limit_radius_by_neighbours), h.value(e.shrink_disagreeing_records);
  h.value(e.refine_where_records_disagree), h.value(e.refine_where_ao_disagrees), h.value(e.lone_record_change_limit);
  h.value(e.lone_record_neighbour_reach), h.value(e.lone_record_reach), h.value(e.space_finest_seeds);
  h.value(e.clamp_across_normals), h.value(e.pretest_inside);
}

void hash_options(key_hasher& h, const bake_options& o) {
  hash_sampler(h, o.sampler);
  hash_cache(h, o.cache);
  h.value(o.use_cache), h.value(o.bounces), h.value(o.indirect_only), h.value(o.min_coverage), h.value(o.offset_texels);
  h.value(o.dilation), h.value(o.stitch_seams), h.value(o.output_sh_l1), h.value(o.output_hl2);
  h.value(o.lights.size());
  for (const light& l : o.lights) {
    h.value(l.type), h.vec(l.color), h.vec(l.position), h.vec(l.direction), h.vec(l.tangent);
    h.value(l.width), h.value(l.height), h.value(l.radius), h.value(l.spot_inner), h.value(l.spot_outer), h.value(l.casts_shadows);
  }
  h.value(o.direct.probe_samples), h.value(o.direct.penumbra_samples), h.value(o.direct.offset_scale);
  h.value(o.strict);
  for (int l : o.shadow_mask_lights) h.value(l);
  h.value(o.ao_distance);
}

// Where the options grow, the key must take the new field: these sizes (x86-64 and AArch64
// Linux, LP64) change with every field added, and this assertion reminds to extend the hash.
#if defined(__LP64__) && (defined(__x86_64__) || defined(__aarch64__))
static_assert(sizeof(cache_expert_options) == 24 && sizeof(cache_options) == 56 && sizeof(integrate_options) == 16 &&
                  sizeof(direct_options) == 12 && sizeof(light) == 76 && sizeof(material) == 52 &&
                  sizeof(raster_options) == 48 && sizeof(sampler_options) == 80 && sizeof(bake_options) == 272 &&
                  sizeof(lightmap_page) == 88 && sizeof(bake_mesh) == 40 && sizeof(scene_desc) == 88,
              "an options struct changed: extend bake_key (bake_key.cpp) with the new field, then update these sizes");
#endif

}  // namespace

std::uint64_t bake_key(const scene_bake_input& input, const bake_options& options) {
  key_hasher h;
  hash_scene(h, input);
  hash_options(h, options);
  return h.result();
}

}  // namespace hemilight
