#include "pipeline/shadows/shadow_page_pool.h"

#include <algorithm>

namespace mp {

void ShadowPagePool::set_capacity(size_t pages) {
  if (pages < capacity_ && extent() > pages) clear();
  capacity_ = pages;
}

void ShadowPagePool::clear() {
  pages_.clear();
  free_.clear();
  next_ = 0;
}

void ShadowPagePool::keep_only(const std::unordered_set<uint64_t>& lights) {
  forget_if([&](const ShadowPageKey& k) { return lights.count(k.light) == 0; });
}

size_t ShadowPagePool::forget_if(const std::function<bool(const ShadowPageKey&)>& stale) {
  size_t forgotten = 0;
  for (auto it = pages_.begin(); it != pages_.end();) {
    if (!stale(it->first)) {
      ++it;
    } else {
      free_.push_back(it->second.physical);
      it = pages_.erase(it);
      ++forgotten;
    }
  }
  return forgotten;
}

uint32_t ShadowPagePool::take_free() {
  if (!free_.empty()) {
    // Lowest first, so the pool buffer stays as small as it can.
    auto lowest = std::min_element(free_.begin(), free_.end());
    uint32_t p = *lowest;
    *lowest = free_.back();
    free_.pop_back();
    return p;
  }
  return next_++;
}

uint32_t ShadowPagePool::extent() const {
  uint32_t e = 0;
  for (const auto& [key, entry] : pages_) e = std::max(e, entry.physical + 1);
  return e;
}

void ShadowPagePool::uncap(const ShadowPageKey& key) {
  auto it = pages_.find(key);
  if (it != pages_.end()) it->second.cap = kUncapped;
}

size_t ShadowPagePool::grant(const std::vector<ShadowPageKey>& requests, const std::vector<uint32_t>& caps,
                             std::vector<Grant>& grants) {
  ++frame_;
  grants.assign(requests.size(), Grant{});
  auto cap_of = [&](size_t i) { return caps.empty() ? kUncapped : caps[i]; };
  size_t granted = 0;
  std::vector<size_t> fresh;
  // Resident pages first: they cost nothing to keep, unless they were
  // rendered only to a nearer depth than asked for now.
  for (size_t i = 0; i < requests.size(); ++i) {
    auto it = pages_.find(requests[i]);
    if (it == pages_.end()) {
      fresh.push_back(i);
      continue;
    }
    it->second.used = frame_;
    const bool again = it->second.cap < cap_of(i);
    if (again) it->second.cap = cap_of(i);
    grants[i] = Grant{it->second.physical, again};
    ++granted;
  }
  // Pages of earlier frames that this one does not use, least recent first.
  std::vector<std::pair<uint64_t, ShadowPageKey>> idle;
  for (const auto& [key, entry] : pages_)
    if (entry.used != frame_) idle.push_back({entry.used, key});
  std::sort(idle.begin(), idle.end(), [](const auto& a, const auto& b) { return a.first < b.first; });
  size_t next_idle = 0;
  for (size_t i : fresh) {
    if (granted >= capacity_) break;
    uint32_t physical;
    if (pages_.size() < capacity_) {
      physical = take_free();
    } else if (next_idle < idle.size()) {
      auto it = pages_.find(idle[next_idle++].second);
      physical = it->second.physical;
      pages_.erase(it);
    } else {
      break;
    }
    pages_[requests[i]] = Entry{physical, frame_, cap_of(i)};
    grants[i] = Grant{physical, true};
    ++granted;
  }
  // Requests beyond the capacity stay without a page (kNone).
  for (size_t i : fresh)
    if (!pages_.count(requests[i])) grants[i] = Grant{kNone, false};
  return granted;
}

}  // namespace mp
