// The physical pages of the shadow maps (kernels/shadow/mp_shadow.h): a pool of
// fixed capacity from which each frame's requested pages get a page, kept
// between frames so that a page whose light and geometry have not changed
// is not rendered again (the viewport's redraws). Pure host bookkeeping.
#pragma once

#include <cstddef>
#include <cstdint>
#include <functional>
#include <unordered_map>
#include <unordered_set>
#include <vector>

namespace mp {

// A page of a light's virtual maps, named so that it means the same in every
// frame while the light and the geometry stay (ShadowLayout's light keys):
// the light's key, its map (ShadowMapInfo::map_id) and the page's absolute
// position in that map.
struct ShadowPageKey {
  uint64_t light = 0;
  int32_t map = 0, x = 0, y = 0;
  bool operator==(const ShadowPageKey& o) const { return light == o.light && map == o.map && x == o.x && y == o.y; }
};

struct ShadowPageKeyHash {
  size_t operator()(const ShadowPageKey& k) const {
    uint64_t h = k.light ^ (uint64_t(uint32_t(k.map)) * 0x9e3779b97f4a7c15ull);
    h ^= (uint64_t(uint32_t(k.x)) << 32 | uint32_t(k.y)) * 0xc2b2ae3d27d4eb4full;
    return size_t(h ^ (h >> 29));
  }
};

class ShadowPagePool {
 public:
  static constexpr uint32_t kNone = 0xffffffffu;  // a request left without a page
  struct Grant {
    uint32_t physical = kNone;
    bool render = false;  // new this frame: the shadow pass renders it
  };
  explicit ShadowPagePool(size_t capacity = 0) : capacity_(capacity) {}

  // Pages the pool may hand out; shrinking below what is resident forgets
  // everything.
  void set_capacity(size_t pages);
  size_t capacity() const { return capacity_; }
  // Forgets the pages of every light not in `lights` (changed or gone).
  void keep_only(const std::unordered_set<uint64_t>& lights);
  // Forgets the pages for which `stale` holds; returns how many.
  size_t forget_if(const std::function<bool(const ShadowPageKey&)>& stale);
  void clear();
  // Gives the requests pages, in order: resident ones keep theirs, new ones
  // take free pages or those least recently used by earlier frames. Grants
  // at most `capacity` pages (the first requests first); returns how many.
  // `caps` (one per request, empty: kUncapped for all): the farthest depth
  // (a positive float's bits) the page must hold what lies in front of; a
  // resident page rendered for a nearer cap is rendered again.
  size_t grant(const std::vector<ShadowPageKey>& requests, const std::vector<uint32_t>& caps,
               std::vector<Grant>& grants);
  size_t grant(const std::vector<ShadowPageKey>& requests, std::vector<Grant>& grants) {
    return grant(requests, {}, grants);
  }
  // Marks a resident page as rendered with everything, whatever its cap.
  void uncap(const ShadowPageKey& key);
  static constexpr uint32_t kUncapped = 0xffffffffu;
  size_t resident() const { return pages_.size(); }
  // One more than the highest physical page in use (the pool buffer's size).
  uint32_t extent() const;

 private:
  struct Entry {
    uint32_t physical;
    uint64_t used;  // the frame that last requested it
    uint32_t cap;   // the depth it was rendered to (kUncapped: all of it)
  };
  uint32_t take_free();
  size_t capacity_;
  std::unordered_map<ShadowPageKey, Entry, ShadowPageKeyHash> pages_;
  std::vector<uint32_t> free_;  // returned physical pages
  uint32_t next_ = 0;           // physical pages never handed out start here
  uint64_t frame_ = 0;
};

}  // namespace mp
