/* Stitched grids: the vertices and micropolygons of a diced sub-patch.
 *
 * A diced sub-patch has an interior grid rate (nu, nv) from its own screen
 * size and, independently, a rate per edge from that edge alone (mp_bound.h).
 * Its mesh is the layout of the Direct3D 11 tessellator's quad domain: the
 * edges carry exactly their own vertices (so a neighbour that shares an edge
 * places the same ones, whatever its interior), the interior is a regular
 * grid of (nu - 1) x (nv - 1) vertices strictly inside, and a strip of
 * micropolygons zips each edge to the interior's outer row or column. Strip
 * steps advance along both sides where they can and along one side only
 * where the rates differ, which makes that step a triangle (a quad with one
 * collapsed side). A sub-patch one micropolygon thin (nv = 1 or nu = 1, with
 * its two short edges of rate 1) is a single strip between its long edges.
 *
 * Storage: each grid owns a slot of (max_grid + 1)^2 vertices, addressed as
 * (i, j) with i fastest. Row 0 holds edge 0 (corner 0 -> 1) and row max_grid
 * edge 2 (corner 3 -> 2), each at its own rate; column 0 holds the inner
 * vertices of edge 3 (corner 0 -> 3) and column max_grid those of edge 1
 * (corner 1 -> 2); interior vertex (i, j) sits at (i, j). Micropolygons per
 * grid are at most (max_grid - 2)^2 + 4 max_grid.
 *
 * Compiles as OpenCL C and C++ (include mp_compat.h and mp_types.h first). */
#ifndef MP_GRID_H
#define MP_GRID_H

MP_INLINE float2 mp_corner(const SubPatch* sp, int k) {
  k &= 3;
  return MP_F2(sp->corner[2 * k], sp->corner[2 * k + 1]);
}

/* The view a sub-patch belongs to: the pass's own (f), or one of several
 * (shadow maps) by the view index in its info. */
MP_INLINE FrameParams mp_subpatch_view(const SubPatch* sp, FrameParams f, const MP_GLOBAL FrameParams* views,
                                       uint view_count) {
  return view_count > 0u ? views[MP_INFO_VIEW(sp->info)] : f;
}

/* The box [u0, u1] x [v0, v1] of a sub-patch's corners in the patch's (u, v). */
MP_INLINE void mp_subpatch_range(const SubPatch* sp, float* u0, float* v0, float* u1, float* v1) {
  *u0 = fmin(fmin(sp->corner[0], sp->corner[2]), fmin(sp->corner[4], sp->corner[6]));
  *u1 = fmax(fmax(sp->corner[0], sp->corner[2]), fmax(sp->corner[4], sp->corner[6]));
  *v0 = fmin(fmin(sp->corner[1], sp->corner[3]), fmin(sp->corner[5], sp->corner[7]));
  *v1 = fmax(fmax(sp->corner[1], sp->corner[3]), fmax(sp->corner[5], sp->corner[7]));
}

/* Whether edge e of a sub-patch runs along the patch's u (splits along v
 * rotate a sub-patch's corners, so edge 0 is not always a u edge). */
MP_INLINE int mp_edge_runs_along_u(const SubPatch* sp, int e) {
  float2 d = mp_corner(sp, e + 1) - mp_corner(sp, e);
  return fabs(d.x) > fabs(d.y);
}

/* Vertex k of n along the segment a -> b. With a, b binary fractions and n a
 * power of two this is exact, so it does not matter from which end or in
 * which sub-patch a shared edge vertex is computed. */
MP_INLINE float2 mp_edge_vertex(float2 a, float2 b, uint k, uint n) {
  return a + (b - a) * ((float)k / (float)n);
}

/* round(a * b / c) for the small non-negative integers of grid indexing. */
MP_INLINE uint mp_round_ratio(uint a, uint b, uint c) { return (2u * a * b + c) / (2u * c); }

/* The number of micropolygon edges along edge e of a diced sub-patch: its
 * rate, or the largest grid for an edge left unrated at the depth limit. */
MP_INLINE uint mp_dice_edge_rate(const SubPatch* sp, uint e, uint mg) {
  uint code = MP_EDGE_CODE(sp->rates, e);
  return code ? MP_CODE_RATE(code) : mg;
}

typedef struct {
  uint mg, nu, nv; /* slot side - 1, interior rates */
  uint n[4];       /* edge rates */
} MpGridShape;

MP_INLINE MpGridShape mp_grid_shape(const SubPatch* sp, uint mg) {
  MpGridShape g;
  g.mg = mg;
  g.nu = MP_INFO_NU(sp->info);
  g.nv = MP_INFO_NV(sp->info);
  for (uint e = 0u; e < 4u; ++e) g.n[e] = mp_dice_edge_rate(sp, e, mg);
  return g;
}

MP_INLINE uint mp_slot(const MpGridShape* g, uint i, uint j) { return j * (g->mg + 1u) + i; }

/* Slot of vertex k (0..n[e]) of edge e, counted from its first corner
 * (edges 0 and 3 from corner 0, edge 1 from corner 1, edge 2 from corner 3). */
MP_INLINE uint mp_edge_slot(const MpGridShape* g, uint e, uint k) {
  if (e == 0u) return mp_slot(g, k, 0u);
  if (e == 2u) return mp_slot(g, k, g->mg);
  if (e == 3u) return k == 0u ? mp_slot(g, 0u, 0u) : k == g->n[3] ? mp_slot(g, 0u, g->mg) : mp_slot(g, 0u, k);
  return k == 0u ? mp_slot(g, g->n[0], 0u) : k == g->n[1] ? mp_slot(g, g->n[2], g->mg) : mp_slot(g, g->mg, k);
}

MP_INLINE int mp_grid_has_interior(const MpGridShape* g) { return g->nu >= 2u && g->nv >= 2u; }

/* Whether the grid uses slot (i, j) (tested before any (u, v) is computed:
 * most slots of a small grid are idle). */
MP_INLINE int mp_slot_live(const MpGridShape* g, uint i, uint j) {
  uint mg = g->mg;
  if (j == 0u) return i <= g->n[0];
  if (j == mg) return i <= g->n[2];
  if (i == 0u) return j < g->n[3];
  if (i == mg) return j < g->n[1];
  return mp_grid_has_interior(g) && i < g->nu && j < g->nv;
}

/* The (u, v) on the patch of slot (i, j), if the grid uses that slot. */
MP_INLINE int mp_slot_uv(const SubPatch* sp, const MpGridShape* g, uint i, uint j, float2* uv) {
  if (!mp_slot_live(g, i, j)) return 0;
  float2 c0 = mp_corner(sp, 0), c1 = mp_corner(sp, 1), c2 = mp_corner(sp, 2), c3 = mp_corner(sp, 3);
  uint mg = g->mg;
  if (j == 0u) *uv = mp_edge_vertex(c0, c1, i, g->n[0]);
  else if (j == mg) *uv = mp_edge_vertex(c3, c2, i, g->n[2]);
  else if (i == 0u) *uv = mp_edge_vertex(c0, c3, j, g->n[3]);
  else if (i == mg) *uv = mp_edge_vertex(c1, c2, j, g->n[1]);
  else {
    float s = (float)i / (float)g->nu, t = (float)j / (float)g->nv;
    *uv = (1.0f - t) * ((1.0f - s) * c0 + s * c1) + t * ((1.0f - s) * c3 + s * c2);
  }
  return 1;
}

/* Vertices of a grid: its edges' (corners once) and the interior's. */
MP_INLINE uint mp_grid_vertices(const MpGridShape* g) {
  uint interior = mp_grid_has_interior(g) ? (g->nu - 1u) * (g->nv - 1u) : 0u;
  return g->n[0] + g->n[1] + g->n[2] + g->n[3] + interior;
}

/* Slot (i, j) of a grid's vertex number o (o < mp_grid_vertices): edge 0,
 * edge 2, the inner vertices of edge 3 and of edge 1, then the interior row
 * by row. */
MP_INLINE void mp_grid_vertex_slot(const MpGridShape* g, uint o, uint* i, uint* j) {
  uint mg = g->mg;
  if (o <= g->n[0]) { *i = o; *j = 0u; return; }
  o -= g->n[0] + 1u;
  if (o <= g->n[2]) { *i = o; *j = mg; return; }
  o -= g->n[2] + 1u;
  if (o < g->n[3] - 1u) { *i = 0u; *j = o + 1u; return; }
  o -= g->n[3] - 1u;
  if (o < g->n[1] - 1u) { *i = mg; *j = o + 1u; return; }
  o -= g->n[1] - 1u;
  *i = 1u + o % (g->nu - 1u);
  *j = 1u + o / (g->nu - 1u);
}

/* The last k with offsets[k] <= x, for an ascending offsets[0, count). */
MP_INLINE uint mp_find_grid(const MP_GLOBAL uint* offsets, uint count, uint x) {
  uint lo = 0u, hi = count - 1u;
  while (lo < hi) {
    uint mid = (lo + hi + 1u) >> 1;
    if (offsets[mid] <= x) lo = mid;
    else hi = mid - 1u;
  }
  return lo;
}

/* The grid vertex that work-item `gid` of a dice or shade launch handles:
 * vertex_offsets[0, count] holds each grid's first vertex and, last, the
 * batch's total (so a launch has exactly one work-item per vertex). Gives
 * the sub-patch, the vertex's slot (i, j), its (u, v) and its index in the
 * grid buffers; 0 for work-items past the total. */
MP_INLINE int mp_grid_vertex(uint gid, uint count, const MP_GLOBAL uint* vertex_offsets, int max_grid,
                             const MP_GLOBAL SubPatch* diceable, SubPatch* sp, uint* i, uint* j, float2* uv,
                             ulong* index) {
  if (count == 0u || gid >= vertex_offsets[count]) return 0;
  uint k = mp_find_grid(vertex_offsets, count, gid);
  *sp = diceable[k];
  MpGridShape g = mp_grid_shape(sp, (uint)max_grid);
  mp_grid_vertex_slot(&g, gid - vertex_offsets[k], i, j);
  uint stride = (uint)max_grid + 1u;
  *index = (ulong)k * stride * stride + mp_slot(&g, *i, *j);
  return mp_slot_uv(sp, &g, *i, *j, uv);
}

/* Micropolygons of a grid: the interior's quads, then the four strips
 * (edges 0, 1, 2, 3) or the one strip of a thin grid. */
MP_INLINE uint mp_grid_micropolygons(const MpGridShape* g) {
  if (g->nv == 1u) return max(g->n[0], g->n[2]);
  if (g->nu == 1u) return max(g->n[3], g->n[1]);
  uint iu = g->nu - 2u, iv = g->nv - 2u;
  return iu * iv + max(g->n[0], iu) + max(g->n[1], iv) + max(g->n[2], iu) + max(g->n[3], iv);
}

/* The most micropolygons a grid of a slot of side mg + 1 can have. */
MP_INLINE uint mp_grid_max_micropolygons(uint mg) { return (mg > 2u ? (mg - 2u) * (mg - 2u) : 0u) + 4u * mg; }

/* Step s of a strip of `steps` zipping a side of na segments to one of nb:
 * the vertex indices where the step starts and ends on each side. */
MP_INLINE void mp_strip_step(uint s, uint steps, uint na, uint nb, uint* a0, uint* a1, uint* b0, uint* b1) {
  *a0 = mp_round_ratio(s, na, steps);
  *a1 = mp_round_ratio(s + 1u, na, steps);
  *b0 = mp_round_ratio(s, nb, steps);
  *b1 = mp_round_ratio(s + 1u, nb, steps);
}

/* Slots of micropolygon m's corners, counter-clockwise in (u, v) like the
 * sub-patch (q[0] -> q[1] -> q[2] -> q[3]); 0 past the last micropolygon. */
MP_INLINE int mp_grid_micropolygon(const MpGridShape* g, uint m, uint* q) {
  uint a0, a1, b0, b1;
  if (m >= mp_grid_micropolygons(g)) return 0;
  if (g->nv == 1u || g->nu == 1u) {
    int across_v = g->nv == 1u; /* edge 0 to edge 2; else edge 3 to edge 1 */
    uint na = across_v ? g->n[0] : g->n[3], nb = across_v ? g->n[2] : g->n[1], steps = max(na, nb);
    mp_strip_step(m, steps, na, nb, &a0, &a1, &b0, &b1);
    if (across_v) {
      q[0] = mp_edge_slot(g, 0u, a0), q[1] = mp_edge_slot(g, 0u, a1);
      q[2] = mp_edge_slot(g, 2u, b1), q[3] = mp_edge_slot(g, 2u, b0);
    } else {
      q[0] = mp_edge_slot(g, 3u, a0), q[1] = mp_edge_slot(g, 1u, b0);
      q[2] = mp_edge_slot(g, 1u, b1), q[3] = mp_edge_slot(g, 3u, a1);
    }
    return 1;
  }
  uint iu = g->nu - 2u, iv = g->nv - 2u;
  if (m < iu * iv) {
    uint a = m % iu + 1u, b = m / iu + 1u;
    q[0] = mp_slot(g, a, b), q[1] = mp_slot(g, a + 1u, b);
    q[2] = mp_slot(g, a + 1u, b + 1u), q[3] = mp_slot(g, a, b + 1u);
    return 1;
  }
  m -= iu * iv;
  for (uint e = 0u; e < 4u; ++e) {
    uint inner = (e & 1u) ? iv : iu, steps = max(g->n[e], inner);
    if (m >= steps) {
      m -= steps;
      continue;
    }
    mp_strip_step(m, steps, g->n[e], inner, &a0, &a1, &b0, &b1);
    /* The interior's row or column next to edge e, at inner index b. */
    uint row = e == 0u ? 1u : g->nv - 1u, col = e == 3u ? 1u : g->nu - 1u;
    uint i0 = (e & 1u) ? mp_slot(g, col, 1u + b0) : mp_slot(g, 1u + b0, row);
    uint i1 = (e & 1u) ? mp_slot(g, col, 1u + b1) : mp_slot(g, 1u + b1, row);
    uint e0 = mp_edge_slot(g, e, a0), e1 = mp_edge_slot(g, e, a1);
    if (e < 2u) q[0] = e0, q[1] = e1, q[2] = i1, q[3] = i0;
    else if (e == 2u) q[0] = i0, q[1] = i1, q[2] = e1, q[3] = e0;
    else q[0] = e0, q[1] = i0, q[2] = i1, q[3] = e1;
    return 1;
  }
  return 0;
}

/* Slot of the vertex across from vertex k of edge e: on the interior's
 * nearest row or column, or on the opposite edge of a thin grid. */
MP_INLINE uint mp_across_slot(const MpGridShape* g, uint e, uint k) {
  uint ne = g->n[e];
  if (mp_grid_has_interior(g)) {
    uint along = (e & 1u) ? g->nv : g->nu;
    uint x = mp_round_ratio(k, along, ne);
    x = x < 1u ? 1u : x > along - 1u ? along - 1u : x;
    if (e == 0u) return mp_slot(g, x, 1u);
    if (e == 2u) return mp_slot(g, x, g->nv - 1u);
    return mp_slot(g, e == 3u ? 1u : g->nu - 1u, x);
  }
  uint opposite = e ^ 2u;
  return mp_edge_slot(g, opposite, mp_round_ratio(k, g->n[opposite], ne));
}

/* Neighbouring vertex slots of slot (i, j) towards -u, +u, -v and +v (the
 * vertex itself where there is none), for differences across the grid. */
MP_INLINE void mp_grid_neighbours(const MpGridShape* g, uint i, uint j, uint* xm, uint* xp, uint* ym, uint* yp) {
  uint self = mp_slot(g, i, j), mg = g->mg;
  *xm = *xp = *ym = *yp = self;
  if (j == 0u || j == mg) { /* edge 0 or 2, corners included */
    uint e = j == 0u ? 0u : 2u, n = g->n[e];
    if (i > 0u) *xm = mp_edge_slot(g, e, i - 1u);
    if (i < n) *xp = mp_edge_slot(g, e, i + 1u);
    uint across = i == 0u ? mp_edge_slot(g, 3u, e == 0u ? 1u : g->n[3] - 1u)
                  : i == n ? mp_edge_slot(g, 1u, e == 0u ? 1u : g->n[1] - 1u)
                           : mp_across_slot(g, e, i);
    if (e == 0u) *yp = across;
    else *ym = across;
    return;
  }
  if (i == 0u || i == mg) { /* inner vertices of edge 3 or 1 */
    uint e = i == 0u ? 3u : 1u;
    *ym = mp_edge_slot(g, e, j - 1u);
    *yp = mp_edge_slot(g, e, j + 1u);
    if (e == 3u) *xp = mp_across_slot(g, 3u, j);
    else *xm = mp_across_slot(g, 1u, j);
    return;
  }
  *xm = i > 1u ? mp_slot(g, i - 1u, j) : mp_edge_slot(g, 3u, mp_round_ratio(j, g->n[3], g->nv));
  *xp = i + 1u < g->nu ? mp_slot(g, i + 1u, j) : mp_edge_slot(g, 1u, mp_round_ratio(j, g->n[1], g->nv));
  *ym = j > 1u ? mp_slot(g, i, j - 1u) : mp_edge_slot(g, 0u, mp_round_ratio(i, g->n[0], g->nu));
  *yp = j + 1u < g->nv ? mp_slot(g, i, j + 1u) : mp_edge_slot(g, 2u, mp_round_ratio(i, g->n[2], g->nu));
}

/* One step along u and one along v from slot (i, j): towards +u and +v,
 * or -u and -v on the far border. */
MP_INLINE void mp_grid_steps(const MpGridShape* g, uint i, uint j, uint* sx, uint* sy) {
  uint here = mp_slot(g, i, j), xm, xp, ym, yp;
  mp_grid_neighbours(g, i, j, &xm, &xp, &ym, &yp);
  *sx = xp != here ? xp : xm;
  *sy = yp != here ? yp : ym;
}

/* Whether grid vertex (i, j), whose normal faces away from the viewer, has a
 * neighbour whose normal faces it: the vertex then lies within one
 * micropolygon of the surface's contour. There a smooth surface folds, both
 * sides project to the same side of the contour, and the side facing the
 * viewer is in front (always, seen from outside a solid); a micropolygon
 * straddling the contour shows that side, as Cycles' ray hits the triangle
 * facing it. Shading the vertex past the contour as the surface's back would
 * light the silhouette from the wrong side. A surface seen from behind, with
 * no contour on it, keeps every vertex facing away. `base` is the grid's
 * first slot in grid_p and grid_n. */
MP_INLINE int mp_grid_beside_contour(const MP_GLOBAL float4* grid_p, const MP_GLOBAL float4* grid_n, ulong base,
                                     const MpGridShape* g, uint i, uint j, int ortho) {
  uint s[4];
  mp_grid_neighbours(g, i, j, &s[0], &s[1], &s[2], &s[3]);
  for (int k = 0; k < 4; ++k) {
    float3 p = MP_XYZ(grid_p[base + s[k]]), n = MP_XYZ(grid_n[base + s[k]]);
    float3 v = ortho ? MP_F3(0.0f, 0.0f, 1.0f) : -p;
    if (dot(n, v) > 0.0f) return 1;
  }
  return 0;
}

/* Whether a patch's material is opaque whatever its shading: no alpha
 * program and a full fixed opacity. Its grids' depth needs no shading, so
 * the camera's samplers can resolve it first (visibility first,
 * MP_SAMPLE_OPAQUE_DEPTH in stages/mp_raster.h). */
MP_INLINE int mp_material_opaque(const MP_GLOBAL DeviceMaterial* materials, const MP_GLOBAL uint* patch_info,
                                 uint patch) {
  const MP_GLOBAL DeviceMaterial* m = materials + patch_info[4 * (ulong)patch + 1];
  return !(m->program[3] > 0.0f) && m->opacity[3] >= 1.0f;
}

/* Whether shading skips the grid vertex at `index` of the grid buffers:
 * visibility first found its grid, opaque, owning no sample (`visible`: a
 * byte per grid slot, or none when the view shades every grid). */
MP_INLINE int mp_grid_unseen(const MP_GLOBAL uchar* visible, ulong index, int max_grid,
                             const MP_GLOBAL DeviceMaterial* materials, const MP_GLOBAL uint* patch_info, uint patch) {
  ulong side = (ulong)max_grid + 1u;
  return visible && !visible[index / (side * side)] && mp_material_opaque(materials, patch_info, patch);
}

#endif
