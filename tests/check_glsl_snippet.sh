#!/usr/bin/env bash
# Compiles include/hemilight/shaders/cubemap_fixup.glsl inside a tiny fragment shader with
# glslangValidator (Debian: glslang-tools), so the snippet cannot rot. Usage: check_glsl_snippet.sh
# <glslangValidator> <repository root>. Used by .ci/run and by the ctest test glsl_snippet.
set -euo pipefail
validator=$1
root=$2
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
{
  echo '#version 330 core'
  cat "$root/include/hemilight/shaders/cubemap_fixup.glsl"
  cat <<'GLSL'
uniform samplerCube env;
uniform float top_size;
uniform float lod;
in vec3 dir;
out vec4 color;
void main() {
  color = textureLod(env, hemilight_cubemap_fixup_lookup(dir, top_size, lod), lod)
        + texture(env, hemilight_cubemap_fixup_lookup(dir, top_size, -1.0));
}
GLSL
} > "$tmp/fixup.frag"
"$validator" "$tmp/fixup.frag"
echo "cubemap_fixup.glsl compiles with $validator"
