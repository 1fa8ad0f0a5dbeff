// hemilight/shaders/cubemap_fixup.glsl — the runtime lookup fixup for cube maps filtered with
// hemilight's STRETCH mapping (HEMILIGHT_EDGE_FIXUP_STRETCH), for hardware or APIs without
// seamless cube-map filtering. Same behaviour as hemilight::fixup_lookup (C++) and
// hemilight_cubemap_fixup_lookup (C); see include/hemilight/cubemap.hpp and docs/cubemap.md.
//
// Include it (paste it, or #include with GL_ARB_shading_language_include / a preprocessor) in
// GLSL 1.30+ / GLSL ES 3.00+ code and sample with the result:
//   color = textureLod(env, hemilight_cubemap_fixup_lookup(dir, float(top_size), lod), lod);
//   color = texture(env, hemilight_cubemap_fixup_lookup(dir, float(size), -1.0));  // one level
//
// size: the top-level face size in texels (>= 1). lod < 0: the fixed-size form, scale
// (size - 1) / size; lod >= 0: scale max(0, 1 - exp2(lod) / size) (0 at or past the last mip:
// the face centre, where a 1 x 1 stretch face's texel is). The two components other than the
// major one are scaled; ties go to x, then y, then z, so on an edge or corner the result lies
// strictly inside one face. The zero vector returns zero; NaN propagates. Exact for STRETCH
// maps; for WARP maps it is off by up to ~0.2 texel between face centre and edge.
#ifndef HEMILIGHT_CUBEMAP_FIXUP_GLSL
#define HEMILIGHT_CUBEMAP_FIXUP_GLSL

vec3 hemilight_cubemap_fixup_lookup(vec3 d, float size, float lod) {
  float scale = lod < 0.0 ? (size - 1.0) / size : max(0.0, 1.0 - exp2(lod) / size);
  vec3 a = abs(d);
  if (a.x >= a.y && a.x >= a.z) return vec3(d.x, d.y * scale, d.z * scale);
  if (a.y >= a.z) return vec3(d.x * scale, d.y, d.z * scale);
  return vec3(d.x * scale, d.y * scale, d.z);
}

#endif
