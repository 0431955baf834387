// The surface record (kernels/materials/mp_surface_record.h) that carries a
// material program's closures to the light program: every field of every
// stored closure and normal comes back bit for bit, records laid out slot by
// slot do not overlap, and a skipped record reads as holding no surface.
#include <gtest/gtest.h>

#include <string>
#include <vector>

#include "cl/device_session.h"
#include "cl/kernel_args.h"
#include "cl/program_cache.h"
#include "core/mp_compat.h"
#include "materials/mp_surface_record.h"

namespace mp {
namespace {

// Record k of `stride` gets a surface whose every field is a distinct
// value of k and the field's number, with k % 11 closures and 1 + k % 4
// normals; it is stored, loaded back into a surface filled with other
// values, and every field the record carries is compared. Odd records are
// skipped after their store, and must then read as empty.
const char* kRoundTrip = R"(
inline float mp_test_value(uint k, uint field) { return (float)(k * 1000u + field) * 0.25f - 7.0f; }
inline int mp_test_int(uint k, uint field) { return (int)(k * 1000u + field) - 3; }

__kernel void record_round_trip(__global float4* pool, uint stride, __global uint* mismatches) {
  const uint k = get_global_id(0);
  if (k >= stride) return;
  MpSurface a;
  uint f = 0;
  a.count = (int)(k % (MP_MAX_CLOSURES + 1u));
  a.normals = 1 + (int)(k % MP_MAX_CLOSURE_NORMALS);
  for (int c = 0; c < MP_MAX_CLOSURES; ++c) {
    MpClosure* cl = &a.c[c];
    cl->weight = (float3)(mp_test_value(k, f), mp_test_value(k, f + 1), mp_test_value(k, f + 2)), f += 3;
    cl->f0 = (float3)(mp_test_value(k, f), mp_test_value(k, f + 1), mp_test_value(k, f + 2)), f += 3;
    cl->f82 = (float3)(mp_test_value(k, f), mp_test_value(k, f + 1), mp_test_value(k, f + 2)), f += 3;
    cl->tangent = (float3)(mp_test_value(k, f), mp_test_value(k, f + 1), mp_test_value(k, f + 2)), f += 3;
    cl->a = mp_test_value(k, f++), cl->b = mp_test_value(k, f++);
    cl->kind = mp_test_int(k, f++), cl->fresnel = mp_test_int(k, f++);
    cl->slot = mp_test_int(k, f++), cl->multiscatter = mp_test_int(k, f++);
    cl->film = mp_test_value(k, f++), cl->film_ior = mp_test_value(k, f++);
  }
  for (int n = 0; n < MP_MAX_CLOSURE_NORMALS; ++n) {
    a.normal[n] = (float3)(mp_test_value(k, f), mp_test_value(k, f + 1), mp_test_value(k, f + 2)), f += 3;
    a.normal_mode[n] = mp_test_int(k, f++);
  }
  a.emission = (float3)(mp_test_value(k, f), mp_test_value(k, f + 1), mp_test_value(k, f + 2)), f += 3;
  a.transparent = (float3)(mp_test_value(k, f), mp_test_value(k, f + 1), mp_test_value(k, f + 2)), f += 3;
  a.holdout = mp_test_value(k, f++);
  a.dropped = mp_test_int(k, f++);
  const float alpha = mp_test_value(k, f++), spread2 = mp_test_value(k, f++);
  const uint index = k * 7u + 1u, object = k + 3u;
  const int faced = (int)(k % 2u);
  mp_record_store(pool, stride, k, &a, index, object, faced, alpha, spread2);
  MpSurface b = a;
  for (int c = 0; c < MP_MAX_CLOSURES; ++c) {
    b.c[c].weight = b.c[c].f0 = b.c[c].f82 = b.c[c].tangent = (float3)(-1.0f);
    b.c[c].a = b.c[c].b = b.c[c].film = b.c[c].film_ior = -1.0f;
    b.c[c].kind = b.c[c].fresnel = b.c[c].slot = b.c[c].multiscatter = -1;
  }
  for (int n = 0; n < MP_MAX_CLOSURE_NORMALS; ++n) b.normal[n] = (float3)(-1.0f), b.normal_mode[n] = -1;
  b.count = b.normals = b.dropped = -1;
  b.emission = b.transparent = (float3)(-1.0f);
  b.holdout = -1.0f;
  int4 head;
  float alpha_b = -1.0f, spread2_b = -1.0f;
  uint wrong = 0;
  if (!mp_record_load(pool, stride, k, &b, &head, &alpha_b, &spread2_b)) wrong += 1000u;
  wrong += head.y != (int)index || head.z != (int)object || head.w != faced;
  wrong += alpha_b != alpha || spread2_b != spread2;
  wrong += b.count != a.count || b.normals != a.normals || b.dropped != a.dropped || b.holdout != a.holdout;
  wrong += any(b.emission != a.emission) || any(b.transparent != a.transparent);
  for (int n = 0; n < a.normals; ++n) wrong += any(b.normal[n] != a.normal[n]) || b.normal_mode[n] != a.normal_mode[n];
  for (int c = 0; c < a.count; ++c) {
    const MpClosure x = a.c[c], y = b.c[c];
    wrong += any(x.weight != y.weight) || any(x.f0 != y.f0) || any(x.f82 != y.f82) || any(x.tangent != y.tangent);
    wrong += x.a != y.a || x.b != y.b || x.film != y.film || x.film_ior != y.film_ior;
    wrong += x.kind != y.kind || x.fresnel != y.fresnel || x.slot != y.slot || x.multiscatter != y.multiscatter;
  }
  if (k % 2u == 1u) {
    mp_record_skip(pool, stride, k);
    if (mp_record_load(pool, stride, k, &b, &head, &alpha_b, &spread2_b)) wrong += 1u;
  }
  mismatches[k] = wrong;
}
)";

TEST(SurfaceRecord, EveryFieldComesBackAndSkippedRecordsAreEmpty) {
  DeviceSession session("");
  const BuiltProgram built = build_program_cached(
      session.context(), session.device(), assemble_light_program_source(false) + kRoundTrip, "-cl-std=CL1.2");
  cl::Kernel kernel(built.program, "record_round_trip");
  // Records side by side in one pool, a stride that is not a power of two.
  const cl_uint stride = 93;
  cl::Buffer pool = session.allocate(size_t(stride) * MP_SURFACE_RECORD_BYTES, "test records");
  cl::Buffer mismatches = session.allocate(stride * sizeof(cl_uint), "test mismatches");
  bind_args(kernel, pool, stride, mismatches);
  session.queue().enqueueNDRangeKernel(kernel, cl::NullRange, cl::NDRange(96), cl::NDRange(32));
  std::vector<cl_uint> wrong(stride);
  session.queue().enqueueReadBuffer(mismatches, CL_TRUE, 0, wrong.size() * sizeof(cl_uint), wrong.data());
  for (cl_uint k = 0; k < stride; ++k) EXPECT_EQ(wrong[k], 0u) << "record " << k;
}

}  // namespace
}  // namespace mp
