// The eight-lane set-up of the AVX2 path (draw_leaf_avx2 and draw_leaf_avx512), included twice
// by rasterizer.cpp: once compiled for AVX2 and once for AVX-512 (VL, BW, DQ: the same 256-bit code
// with 32 registers and EVEX encodings). HEMILIGHT_LEAF_NAME and HEMILIGHT_LEAF_TARGET name the
// member and its target attribute. rasterizer.cpp is compiled with -ffp-contract=off, so the
// AVX-512 build (whose target includes FMA) forms no fused multiply-adds: both builds compute
// the same bits as the scalar path (tested).
// draw_triangle for the AVX2 path, up to eight triangles at a time (a BVH leaf): the same results,
// bit for bit (the same float operations on the same values, in the same order; tested against
// the scalar path). Lane j holds triangle j: its vertices and normal are moved to the local frame
// and tested against the five faces together; each triangle that survives then goes through
// the face stage below, face by face, in leaf order within each face (the scalar path's order
// for every texel).
// log: occlusion culling's front-to-back pass, whose depth tests log their ties (tie_sink_).
template <rasterizer_impl::mode M, bool log>
HEMILIGHT_LEAF_TARGET void raster_detail::rasterizer_impl::HEMILIGHT_LEAF_NAME(const scene::triangle* all, std::uint32_t first,
                                                               std::uint32_t count,
                                                               unsigned face_mask, const simd_frame& sf,
                                                               const frame& basis) {
  stats_.triangles_tested += count;
  tie_log* const ties = log ? tie_sink_ : nullptr;  // read once: the stores below may alias it
  const scene::triangle* tris = all + first;
  const __m256i lane = _mm256_setr_epi32(0, 1, 2, 3, 4, 5, 6, 7);
  const __m256i live = _mm256_cmpgt_epi32(_mm256_set1_epi32(static_cast<int>(count)), lane);
  // Eight consecutive triangles from the per-coordinate arrays (lanes past `count` load the next
  // triangles or the arrays' padding; `live` masks them out below).
  __m256 v[3][3];  // v[vertex][axis], world
  for (int i = 0; i < 3; ++i)
    for (int k = 0; k < 3; ++k) v[i][k] = _mm256_loadu_ps(sf.coordinates[i][k] + first);
  // World edges and their cross product (glm::cross's operations: x.y y.z - y.y x.z, ...).
  __m256 e1[3], e2[3];
  for (int k = 0; k < 3; ++k) {
    e1[k] = _mm256_sub_ps(v[1][k], v[0][k]);
    e2[k] = _mm256_sub_ps(v[2][k], v[0][k]);
  }
  const __m256 c[3] = {_mm256_sub_ps(_mm256_mul_ps(e1[1], e2[2]), _mm256_mul_ps(e2[1], e1[2])),
                       _mm256_sub_ps(_mm256_mul_ps(e1[2], e2[0]), _mm256_mul_ps(e2[2], e1[0])),
                       _mm256_sub_ps(_mm256_mul_ps(e1[0], e2[1]), _mm256_mul_ps(e2[0], e1[1]))};
  // To the local frame (dot8 = frame::to_local's dot). l[i][axis]: vertex i (3: the normal).
  __m256 l[4][3];
  for (int i = 0; i < 3; ++i) {
    const __m256 d[3] = {_mm256_sub_ps(v[i][0], sf.p[0]), _mm256_sub_ps(v[i][1], sf.p[1]),
                         _mm256_sub_ps(v[i][2], sf.p[2])};
    l[i][0] = dot8(d, sf.t);
    l[i][1] = dot8(d, sf.b);
    l[i][2] = dot8(d, sf.n);
  }
  l[3][0] = dot8(c, sf.t);
  l[3][1] = dot8(c, sf.b);
  l[3][2] = dot8(c, sf.n);
  // Faces: rejected when all three vertices lie outside one of the face's frustum planes (the
  // face_planes of outcode()). With a = x - y, b = x + y, c = z - x, d = z + x, e = z - y,
  // f = z + y per vertex ("all three < 0" is max < 0, "all three > 0" is min > 0):
  //   top: c, d, e or f < 0;   +x: a < 0, b < 0, c > 0 or z < 0;   -x: a > 0, b > 0, d > 0 or z < 0;
  //   +y: a > 0, b < 0, e > 0 or z < 0;   -y: a < 0, b > 0, f > 0 or z < 0.
  // Each sum is the scalar test's up to an exact negation (x - z = -(z - x)), so the decisions
  // are the same.
  __m256 q_max[6], q_min[6];
  for (int i = 0; i < 3; ++i) {
    const __m256 x = l[i][0], y = l[i][1], z = l[i][2];
    const __m256 q[6] = {_mm256_sub_ps(x, y), _mm256_add_ps(x, y), _mm256_sub_ps(z, x),
                         _mm256_add_ps(z, x), _mm256_sub_ps(z, y), _mm256_add_ps(z, y)};
    for (int k = 0; k < 6; ++k) {
      q_max[k] = i == 0 ? q[k] : _mm256_max_ps(q_max[k], q[k]);
      q_min[k] = i == 0 ? q[k] : _mm256_min_ps(q_min[k], q[k]);
    }
  }
  const __m256 z_max = _mm256_max_ps(_mm256_max_ps(l[0][2], l[1][2]), l[2][2]);
  const __m256 below = negative8(z_max), a_neg = negative8(q_max[0]), a_pos = positive8(q_min[0]), b_neg = negative8(q_max[1]),
               b_pos = positive8(q_min[1]);
  const __m256 out[5] = {
      _mm256_or_ps(_mm256_or_ps(negative8(q_max[2]), negative8(q_max[3])), _mm256_or_ps(negative8(q_max[4]), negative8(q_max[5]))),
      _mm256_or_ps(_mm256_or_ps(a_neg, b_neg), _mm256_or_ps(positive8(q_min[2]), below)),
      _mm256_or_ps(_mm256_or_ps(a_pos, b_pos), _mm256_or_ps(positive8(q_min[3]), below)),
      _mm256_or_ps(_mm256_or_ps(a_pos, b_neg), _mm256_or_ps(positive8(q_min[4]), below)),
      _mm256_or_ps(_mm256_or_ps(a_neg, b_pos), _mm256_or_ps(positive8(q_min[5]), below))};
  const unsigned lanes = static_cast<unsigned>(_mm256_movemask_ps(_mm256_castsi256_ps(live)));
  // The plane of each triangle (glm::dot(normal, v0)); a plane through the point is seen edge-on
  // and covers no texel centre (draw_triangle's test: plane != 0 and finite).
  const __m256 plane = dot8(l[3], l[0]);
  const __m256 abs_plane = _mm256_andnot_ps(_mm256_set1_ps(-0.0f), plane);
  const unsigned drawable =
      lanes & static_cast<unsigned>(_mm256_movemask_ps(_mm256_and_ps(
                  _mm256_cmp_ps(plane, _mm256_setzero_ps(), _CMP_NEQ_OQ),
                  _mm256_cmp_ps(abs_plane, _mm256_set1_ps(std::numeric_limits<float>::infinity()), _CMP_LT_OQ))));
  unsigned in_face[5] = {};
  unsigned any = 0;
  for (int f = 0; f < 5; ++f) {
    if (!(face_mask >> f & 1u)) continue;
    in_face[f] = ~static_cast<unsigned>(_mm256_movemask_ps(out[f])) & drawable;
    any |= in_face[f];
  }
  if (!any) return;

  // Per lane (v0, v1, v2, normal) of each axis as four floats: the records and the clipping path.
  alignas(32) float axis[3][8][4];
  for (int k = 0; k < 3; ++k) {
    // A 4 x 8 transpose: rows l[0..3][k] -> eight columns of four.
    const __m256 t0 = _mm256_unpacklo_ps(l[0][k], l[1][k]), t1 = _mm256_unpackhi_ps(l[0][k], l[1][k]);
    const __m256 t2 = _mm256_unpacklo_ps(l[2][k], l[3][k]), t3 = _mm256_unpackhi_ps(l[2][k], l[3][k]);
    const __m256 c0 = _mm256_shuffle_ps(t0, t2, _MM_SHUFFLE(1, 0, 1, 0)), c1 = _mm256_shuffle_ps(t0, t2, _MM_SHUFFLE(3, 2, 3, 2));
    const __m256 c2 = _mm256_shuffle_ps(t1, t3, _MM_SHUFFLE(1, 0, 1, 0)), c3 = _mm256_shuffle_ps(t1, t3, _MM_SHUFFLE(3, 2, 3, 2));
    // c0 = columns 0 and 4, c1 = 1 and 5, c2 = 2 and 6, c3 = 3 and 7 (low and high halves).
    _mm_store_ps(axis[k][0], _mm256_castps256_ps128(c0));
    _mm_store_ps(axis[k][1], _mm256_castps256_ps128(c1));
    _mm_store_ps(axis[k][2], _mm256_castps256_ps128(c2));
    _mm_store_ps(axis[k][3], _mm256_castps256_ps128(c3));
    _mm_store_ps(axis[k][4], _mm256_extractf128_ps(c0, 1));
    _mm_store_ps(axis[k][5], _mm256_extractf128_ps(c1, 1));
    _mm_store_ps(axis[k][6], _mm256_extractf128_ps(c2, 1));
    _mm_store_ps(axis[k][7], _mm256_extractf128_ps(c3, 1));
  }
  alignas(32) float plane_of[8];
  _mm256_store_ps(plane_of, plane);
  // A lane's record, filled where it is needed (clipped and big lanes, textured renders): the
  // small triangles of an untextured render need only the plane.
  draw_record rec[8];
  std::uint32_t draw[8] = {};
  const auto record = [&](unsigned j) -> draw_record& {
    rec[j].normal = glm::vec3(axis[0][j][3], axis[1][j][3], axis[2][j][3]);
    rec[j].v0 = glm::vec3(axis[0][j][0], axis[1][j][0], axis[2][j][0]);
    rec[j].plane = plane_of[j];
    rec[j].index = tris[j].index;
    return rec[j];
  };

  // Face by face, all lanes at once (faces cover different texels, so only the order within a
  // face matters, and within a face the lanes are drawn in leaf order, as the scalar path does).
  const int n = n_;
  const __m256 sign = _mm256_set1_ps(-0.0f), zero = _mm256_setzero_ps();
  const __m256 near8 = _mm256_set1_ps(near_), band = _mm256_set1_ps(guard_band);
#if HEMILIGHT_LEAF_WIDE
  // The zero-masked conversions (all lanes kept) are the plain ones; GCC 12 warns about the
  // plain ones' undefined pass-through operand (-Wmaybe-uninitialized, a known false positive).
  const __mmask8 all8 = 0xff;
  const __m512d one8 = _mm512_set1_pd(1.0), half8 = _mm512_set1_pd(0.5), minus_half8 = _mm512_set1_pd(-0.5);
  const __m512d dscale8 = _mm512_set1_pd(0.5 * n * static_cast<double>(sub_one)), zero8 = _mm512_setzero_pd();
#else
  const __m256d one = _mm256_set1_pd(1.0), half = _mm256_set1_pd(0.5), minus_half = _mm256_set1_pd(-0.5);
  const __m256d dscale = _mm256_set1_pd(0.5 * n * static_cast<double>(sub_one)), zero_d = _mm256_setzero_pd();
#endif
  const __m256i zero_i = _mm256_setzero_si256(), ones_i = _mm256_set1_epi32(-1);
  for (int f = 0; f < 5; ++f) {
    const unsigned todo = in_face[f];
    if (!todo) continue;
    stats_.face_triangles += static_cast<std::size_t>(__builtin_popcount(todo));
    // to_clip's face coordinates (u, v, w) of the three vertices and the normal (negation is exact).
    __m256 u[4], vv[4], w[4];
    for (int i = 0; i < 4; ++i) {
      const __m256 x = l[i][0], y = l[i][1], z = l[i][2];
      switch (f) {
        case 0: u[i] = x; vv[i] = y; w[i] = z; break;
        case 1: u[i] = y; vv[i] = z; w[i] = x; break;
        case 2: u[i] = _mm256_xor_ps(y, sign); vv[i] = z; w[i] = _mm256_xor_ps(x, sign); break;
        case 3: u[i] = _mm256_xor_ps(x, sign); vv[i] = z; w[i] = y; break;
        default: u[i] = x; vv[i] = z; w[i] = _mm256_xor_ps(y, sign); break;
      }
    }
    // raster_face's clip codes: lanes with a vertex outside a clip plane are clipped by raster_face.
    __m256 outside = zero;
    for (int i = 0; i < 3; ++i) {
      const __m256 gw = _mm256_mul_ps(band, w[i]);
      outside = _mm256_or_ps(outside, _mm256_or_ps(_mm256_cmp_ps(_mm256_sub_ps(w[i], near8), zero, _CMP_LT_OQ),
                                                   _mm256_cmp_ps(_mm256_sub_ps(gw, u[i]), zero, _CMP_LT_OQ)));
      outside = _mm256_or_ps(outside, _mm256_or_ps(_mm256_cmp_ps(_mm256_add_ps(gw, u[i]), zero, _CMP_LT_OQ),
                                                   _mm256_cmp_ps(_mm256_sub_ps(gw, vv[i]), zero, _CMP_LT_OQ)));
      outside = _mm256_or_ps(outside, _mm256_cmp_ps(_mm256_add_ps(gw, vv[i]), zero, _CMP_LT_OQ));
    }
    const unsigned clipped = static_cast<unsigned>(_mm256_movemask_ps(outside)) & todo;
    // raster_face's projection and snapping in double, four lanes per register: iw = 1 / w,
    // round((u iw + 1) scale), round((v iw + v_offset) scale), halves away from zero. Clipped
    // lanes compute garbage here (w may be <= 0) and are not used.
    __m256i X[3], Y[3];
#if HEMILIGHT_LEAF_WIDE
    // The AVX-512 build: the same double operations on all eight lanes in one register.
    const __m512d v_offset = _mm512_set1_pd(f == 0 ? 1.0 : 0.0);
    for (int i = 0; i < 3; ++i) {
      const __m512d iw = _mm512_div_pd(one8, _mm512_maskz_cvtps_pd(all8, w[i]));
      const __m512d xs = _mm512_mul_pd(_mm512_add_pd(_mm512_mul_pd(_mm512_maskz_cvtps_pd(all8, u[i]), iw), one8), dscale8);
      const __m512d ys = _mm512_mul_pd(_mm512_add_pd(_mm512_mul_pd(_mm512_maskz_cvtps_pd(all8, vv[i]), iw), v_offset), dscale8);
      X[i] = _mm512_maskz_cvttpd_epi32(all8, _mm512_add_pd(xs, _mm512_mask_blend_pd(_mm512_cmp_pd_mask(xs, zero8, _CMP_GE_OQ), minus_half8, half8)));
      Y[i] = _mm512_maskz_cvttpd_epi32(all8, _mm512_add_pd(ys, _mm512_mask_blend_pd(_mm512_cmp_pd_mask(ys, zero8, _CMP_GE_OQ), minus_half8, half8)));
    }
#else
    const __m256d v_offset = _mm256_set1_pd(f == 0 ? 1.0 : 0.0);
    for (int i = 0; i < 3; ++i) {
      __m128i xs_half[2], ys_half[2];
      for (int h = 0; h < 2; ++h) {
        const __m128 uh = h ? _mm256_extractf128_ps(u[i], 1) : _mm256_castps256_ps128(u[i]);
        const __m128 vh = h ? _mm256_extractf128_ps(vv[i], 1) : _mm256_castps256_ps128(vv[i]);
        const __m128 wh = h ? _mm256_extractf128_ps(w[i], 1) : _mm256_castps256_ps128(w[i]);
        const __m256d iw = _mm256_div_pd(one, _mm256_cvtps_pd(wh));
        const __m256d xs = _mm256_mul_pd(_mm256_add_pd(_mm256_mul_pd(_mm256_cvtps_pd(uh), iw), one), dscale);
        const __m256d ys = _mm256_mul_pd(_mm256_add_pd(_mm256_mul_pd(_mm256_cvtps_pd(vh), iw), v_offset), dscale);
        xs_half[h] = _mm256_cvttpd_epi32(_mm256_add_pd(xs, _mm256_blendv_pd(minus_half, half, _mm256_cmp_pd(xs, zero_d, _CMP_GE_OQ))));
        ys_half[h] = _mm256_cvttpd_epi32(_mm256_add_pd(ys, _mm256_blendv_pd(minus_half, half, _mm256_cmp_pd(ys, zero_d, _CMP_GE_OQ))));
      }
      X[i] = _mm256_set_m128i(xs_half[1], xs_half[0]);
      Y[i] = _mm256_set_m128i(ys_half[1], ys_half[0]);
    }
#endif
    const __m256i min_x = _mm256_min_epi32(_mm256_min_epi32(X[0], X[1]), X[2]);
    const __m256i max_x = _mm256_max_epi32(_mm256_max_epi32(X[0], X[1]), X[2]);
    const __m256i min_y = _mm256_min_epi32(_mm256_min_epi32(Y[0], Y[1]), Y[2]);
    const __m256i max_y = _mm256_max_epi32(_mm256_max_epi32(Y[0], Y[1]), Y[2]);
    // Lanes over 120 texels across go to draw_fixed's exact 64-bit paths.
    const __m256i limit = _mm256_set1_epi32(static_cast<int>(avx2_extent));
    const unsigned big = static_cast<unsigned>(_mm256_movemask_ps(_mm256_castsi256_ps(
                             _mm256_or_si256(_mm256_cmpgt_epi32(_mm256_sub_epi32(max_x, min_x), limit),
                                             _mm256_cmpgt_epi32(_mm256_sub_epi32(max_y, min_y), limit))))) &
                         todo & ~clipped;
    // With edge coverage a lane that touches hard texels goes through raster_face (which keeps
    // the unsnapped projected vertices for edge_texels); every lane has a draw of its own per
    // face (see bind).
    unsigned via_face = clipped;
    if (M == mode::depth && edge_) {
      for (unsigned m = todo; m; m &= m - 1) draw[__builtin_ctz(m)] = 0;
      if (edges_.hard_faces >> f & 1u) {
        alignas(32) std::int32_t lx[8], hx[8], ly[8], hy[8];
        _mm256_store_si256(reinterpret_cast<__m256i*>(lx), min_x);
        _mm256_store_si256(reinterpret_cast<__m256i*>(hx), max_x);
        _mm256_store_si256(reinterpret_cast<__m256i*>(ly), min_y);
        _mm256_store_si256(reinterpret_cast<__m256i*>(hy), max_y);
        const std::int64_t rows = f == 0 ? n : n / 2;
        for (unsigned m = todo & ~clipped; m; m &= m - 1) {
          const unsigned j = static_cast<unsigned>(__builtin_ctz(m));
          // The texels the lane's box overlaps (draw_fixed's test), clamped to the face.
          const std::int64_t c0 = std::max<std::int64_t>(floor_sub(std::int64_t(lx[j]) - 1), 0);
          const std::int64_t c1 = std::min<std::int64_t>(ceil_sub(std::int64_t(hx[j]) + 1) - 1, n - 1);
          const std::int64_t r0 = std::max<std::int64_t>(floor_sub(std::int64_t(ly[j]) - 1), 0);
          const std::int64_t r1 = std::min<std::int64_t>(ceil_sub(std::int64_t(hy[j]) + 1) - 1, rows - 1);
          if (c0 <= c1 && r0 <= r1 && edge_box_is_hard(f, c0, c1, r0, r1)) via_face |= 1u << j;
        }
      }
    }
    // Texels whose centre (k + 1/2) lies in the box, clamped to the face (ceil_sub, floor_sub).
    const __m256i halfi = _mm256_set1_epi32(static_cast<int>(sub_half));
    const __m256i x_begin = _mm256_max_epi32(
        _mm256_sub_epi32(zero_i, _mm256_srai_epi32(_mm256_sub_epi32(halfi, min_x), sub_bits)), zero_i);
    const __m256i x_end = _mm256_min_epi32(_mm256_srai_epi32(_mm256_sub_epi32(max_x, halfi), sub_bits),
                                           _mm256_set1_epi32(n - 1));
    const __m256i y_begin = _mm256_max_epi32(
        _mm256_sub_epi32(zero_i, _mm256_srai_epi32(_mm256_sub_epi32(halfi, min_y), sub_bits)), zero_i);
    const __m256i y_end = _mm256_min_epi32(_mm256_srai_epi32(_mm256_sub_epi32(max_y, halfi), sub_bits),
                                           _mm256_set1_epi32((f == 0 ? n : n / 2) - 1));
    const unsigned empty = static_cast<unsigned>(_mm256_movemask_ps(_mm256_castsi256_ps(
        _mm256_or_si256(_mm256_cmpgt_epi32(x_begin, x_end), _mm256_cmpgt_epi32(y_begin, y_end)))));
    // Edges k (vertex k to k + 1) and twice the signed area, dy0 dx2 - dx0 dy2; clockwise lanes
    // swap vertices 1 and 2.
    __m256i dx[3], dy[3];
    for (int k = 0; k < 3; ++k) {
      dx[k] = _mm256_sub_epi32(X[(k + 1) % 3], X[k]);
      dy[k] = _mm256_sub_epi32(Y[(k + 1) % 3], Y[k]);
    }
    const __m256i area = _mm256_sub_epi32(_mm256_mullo_epi32(dy[0], dx[2]), _mm256_mullo_epi32(dx[0], dy[2]));
    const __m256i cw = _mm256_cmpgt_epi32(zero_i, area);
    const unsigned flat = static_cast<unsigned>(_mm256_movemask_ps(_mm256_castsi256_ps(_mm256_cmpeq_epi32(area, zero_i))));
    const __m256i x1 = _mm256_blendv_epi8(X[1], X[2], cw), x2 = _mm256_blendv_epi8(X[2], X[1], cw);
    const __m256i y1 = _mm256_blendv_epi8(Y[1], Y[2], cw), y2 = _mm256_blendv_epi8(Y[2], Y[1], cw);
    const __m256i px[3] = {X[0], x1, x2}, py[3] = {Y[0], y1, y2};
    const __m256i ox = _mm256_add_epi32(_mm256_slli_epi32(x_begin, sub_bits), halfi);
    const __m256i oy = _mm256_add_epi32(_mm256_slli_epi32(y_begin, sub_bits), halfi);
    alignas(32) std::int32_t base[3][8], sx[3][8], sy[3][8];
    for (int k = 0; k < 3; ++k) {
      const __m256i ddx = _mm256_sub_epi32(px[(k + 1) % 3], px[k]), ddy = _mm256_sub_epi32(py[(k + 1) % 3], py[k]);
      // Owned edges (dy > 0, or dy = 0 and dx < 0) keep their ties; the others get bias 1.
      const __m256i owned = _mm256_or_si256(_mm256_cmpgt_epi32(ddy, zero_i),
                                            _mm256_and_si256(_mm256_cmpeq_epi32(ddy, zero_i), _mm256_cmpgt_epi32(zero_i, ddx)));
      _mm256_store_si256(reinterpret_cast<__m256i*>(base[k]),
                         _mm256_add_epi32(_mm256_sub_epi32(_mm256_mullo_epi32(ddx, _mm256_sub_epi32(oy, py[k])),
                                                           _mm256_mullo_epi32(ddy, _mm256_sub_epi32(ox, px[k]))),
                                          _mm256_xor_si256(owned, ones_i)));  // -(owned ? 0 : 1)
      _mm256_store_si256(reinterpret_cast<__m256i*>(sx[k]), _mm256_slli_epi32(_mm256_sub_epi32(zero_i, ddy), sub_bits));
      _mm256_store_si256(reinterpret_cast<__m256i*>(sy[k]), _mm256_slli_epi32(ddx, sub_bits));
    }
    // face_setup::prepare's depth plane, four lanes of double at a time.
    alignas(64) double z00[8], dzdy[8];
    alignas(32) float dzdx[8];
#if HEMILIGHT_LEAF_WIDE
    {
      const __m512d step = _mm512_set1_pd(texel_step_), u0 = _mm512_set1_pd(first_centre_);
      const __m512d v0 = f == 0 ? u0 : _mm512_set1_pd(0.5 * texel_step_);
      const __m512d inv_k = _mm512_div_pd(one8, _mm512_maskz_cvtps_pd(all8, plane));
      const __m512d nud = _mm512_maskz_cvtps_pd(all8, u[3]), nvd = _mm512_maskz_cvtps_pd(all8, vv[3]), nwd = _mm512_maskz_cvtps_pd(all8, w[3]);
      _mm256_store_ps(dzdx, _mm512_maskz_cvtpd_ps(all8, _mm512_mul_pd(_mm512_mul_pd(nud, step), inv_k)));
      _mm512_store_pd(dzdy, _mm512_mul_pd(_mm512_mul_pd(nvd, step), inv_k));
      _mm512_store_pd(z00, _mm512_mul_pd(_mm512_add_pd(_mm512_add_pd(nwd, _mm512_mul_pd(nud, u0)), _mm512_mul_pd(nvd, v0)), inv_k));
    }
#else
    {
      const __m256d step = _mm256_set1_pd(texel_step_), u0 = _mm256_set1_pd(first_centre_);
      const __m256d v0 = f == 0 ? u0 : _mm256_set1_pd(0.5 * texel_step_);
      for (int h = 0; h < 2; ++h) {
        const __m128 nu = h ? _mm256_extractf128_ps(u[3], 1) : _mm256_castps256_ps128(u[3]);
        const __m128 nv = h ? _mm256_extractf128_ps(vv[3], 1) : _mm256_castps256_ps128(vv[3]);
        const __m128 nw = h ? _mm256_extractf128_ps(w[3], 1) : _mm256_castps256_ps128(w[3]);
        const __m128 pk = h ? _mm256_extractf128_ps(plane, 1) : _mm256_castps256_ps128(plane);
        const __m256d inv_k = _mm256_div_pd(one, _mm256_cvtps_pd(pk));
        const __m256d nud = _mm256_cvtps_pd(nu), nvd = _mm256_cvtps_pd(nv), nwd = _mm256_cvtps_pd(nw);
        _mm_store_ps(dzdx + 4 * h, _mm256_cvtpd_ps(_mm256_mul_pd(_mm256_mul_pd(nud, step), inv_k)));
        _mm256_store_pd(dzdy + 4 * h, _mm256_mul_pd(_mm256_mul_pd(nvd, step), inv_k));
        _mm256_store_pd(z00 + 4 * h,
                        _mm256_mul_pd(_mm256_add_pd(_mm256_add_pd(nwd, _mm256_mul_pd(nud, u0)), _mm256_mul_pd(nvd, v0)), inv_k));
      }
    }
#endif
    alignas(32) std::int32_t xb[8], xe[8], yb[8], ye[8], vx[3][8], vy[3][8];
    _mm256_store_si256(reinterpret_cast<__m256i*>(xb), x_begin);
    _mm256_store_si256(reinterpret_cast<__m256i*>(xe), x_end);
    _mm256_store_si256(reinterpret_cast<__m256i*>(yb), y_begin);
    _mm256_store_si256(reinterpret_cast<__m256i*>(ye), y_end);
    if (big) {
      for (int i = 0; i < 3; ++i) {
        _mm256_store_si256(reinterpret_cast<__m256i*>(vx[i]), X[i]);
        _mm256_store_si256(reinterpret_cast<__m256i*>(vy[i]), Y[i]);
      }
    }
    const std::size_t face_offset = hemicube_face_offset(n, static_cast<hemicube_face>(f));
    float* depth = depth_.data() + face_offset;
    std::uint32_t* ids = ids_.data() + face_offset;
    std::uint32_t* counts = M == mode::count ? counts_->data() + face_offset : nullptr;
    for (unsigned m = todo; m; m &= m - 1) {
      const unsigned j = static_cast<unsigned>(__builtin_ctz(m));
      const unsigned bit = 1u << j;
      const scene::triangle& tri = tris[j];
      if (via_face & bit) {
        draw_record& r = record(j);
        const glm::vec3 local[3] = {r.v0, glm::vec3(axis[0][j][1], axis[1][j][1], axis[2][j][1]),
                                    glm::vec3(axis[0][j][2], axis[1][j][2], axis[2][j][2])};
        raster_face<M>(f, local, r, draw[j], basis, tri);
        continue;
      }
      if (big & bit) {
        face_setup fs;
        const std::int64_t bx[3] = {vx[0][j], vx[1][j], vx[2][j]}, by[3] = {vy[0][j], vy[1][j], vy[2][j]};
        draw_fixed<M>(f, bx, by, fs, record(j), draw[j], basis, tri);
        continue;
      }
      if ((empty | flat) & bit) continue;
      if (draw[j] == 0) draw[j] = commit_record(plane_of[j], tri, textured_ ? &record(j) : nullptr, basis);
      small_triangle_avx2_body<M == mode::count, log>(&base[0][j], &sx[0][j], &sy[0][j], 8, xb[j], xe[j], yb[j], ye[j], n,
                                                      depth, ids, counts, z00[j], dzdy[j], dzdx[j], draw[j], ties);
    }
  }
}
