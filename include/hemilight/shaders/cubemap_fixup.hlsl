// hemilight/shaders/cubemap_fixup.hlsl — the runtime lookup fixup for cube maps filtered with
// hemilight's STRETCH mapping (HEMILIGHT_EDGE_FIXUP_STRETCH). Same behaviour as
// hemilight::fixup_lookup (C++), hemilight_cubemap_fixup_lookup (C) and cubemap_fixup.glsl; see
// include/hemilight/cubemap.hpp and docs/cubemap.md. D3D10+ filters cube maps seamlessly, so this
// matters for D3D9-class targets and for consoles or ports that sample faces separately:
//   color = env.SampleLevel(smp, hemilight_cubemap_fixup_lookup(dir, top_size, lod), lod);
//
// size: the top-level face size in texels (>= 1). lod < 0: the fixed-size form, scale
// (size - 1) / size; lod >= 0: scale max(0, 1 - exp2(lod) / size). The two components other than
// the major one are scaled; ties go to x, then y, then z. The zero vector returns zero.
#ifndef HEMILIGHT_CUBEMAP_FIXUP_HLSL
#define HEMILIGHT_CUBEMAP_FIXUP_HLSL

float3 hemilight_cubemap_fixup_lookup(float3 d, float size, float lod) {
  float scale = lod < 0.0 ? (size - 1.0) / size : max(0.0, 1.0 - exp2(lod) / size);
  float3 a = abs(d);
  if (a.x >= a.y && a.x >= a.z) return float3(d.x, d.y * scale, d.z * scale);
  if (a.y >= a.z) return float3(d.x * scale, d.y, d.z * scale);
  return float3(d.x * scale, d.y * scale, d.z);
}

#endif
