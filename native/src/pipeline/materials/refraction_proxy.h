// Triangle proxies of refracting objects, for the paths Glass, Refraction
// and Principled Transmission follow through their object's own shape
// (kernels/geometry/mp_refract_trace.h holds the layout and the traversal).
#pragma once

#include <cstdint>
#include <glm/glm.hpp>
#include <string>
#include <vector>

#include "micropoly/scene.h"
#include "subdiv/patch_buffer.h"

namespace mp {

struct RefractionProxies {
  std::vector<glm::vec4> nodes;  // 2 float4 per node
  std::vector<glm::vec4> tris;   // 6 float4 per triangle
  std::vector<uint32_t> roots;   // per object: its root node, MP_REFRACT_NONE without a proxy
};

// Triangles the proxies of one scene may take in all (about 96 bytes each,
// plus their tree), and one object at most.
constexpr size_t kRefractionTriangleBudget = size_t(1) << 20;
constexpr size_t kRefractionObjectTriangles = size_t(1) << 18;

// A proxy triangle: corners wound so that their cross product faces out of
// the object, and the surface's normals there.
struct ProxyTriangle {
  glm::vec3 p[3], n[3];
};

// Adds one object's proxy (its triangles reordered into a bounding volume
// hierarchy) to `out`; returns its root node.
uint32_t append_refraction_proxy(std::vector<ProxyTriangle>& tris, RefractionProxies& out);

// Whether a material program can refract with the material's node values
// `params`: a Glass or Refraction node, or a Principled BSDF whose
// Transmission is not the constant 0 (a literal or a value of 0).
bool program_refracts(const std::string& source, const std::vector<float>& params);

// Proxies for every object (MP_PATCH_OBJECT of the patches' flags, object
// count `objects`) wearing a material for which `refracts` is true: the
// patches' surfaces (camera space, as `patches` holds them, undisplaced)
// tessellated uniformly, as many steps per patch as the budgets allow, in a
// bounding volume hierarchy per object. An object too large for one step
// per patch within the budgets gets none.
RefractionProxies build_refraction_proxies(const PatchBuffer& patches, size_t objects,
                                           const std::vector<bool>& refracts);

}  // namespace mp
