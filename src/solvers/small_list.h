#pragma once
// Internal: a list of trivially copyable values (slot and clique ids, keys,
// a variable's numbers)
// held inline up to N entries and on the heap beyond. A Bayes tree over a
// long chain keeps a few such lists per step (a clique's factors, children
// and separator, a factor's keys, a variable's factors); as std::vectors
// each was a heap block of its own, a tenth of a full-history run's memory.
#include <algorithm>
#include <cstdint>
#include <cstring>
#include <type_traits>
#include <vector>

namespace gssm::internal {

template <class T, std::uint32_t N>
class SmallList {
  static_assert(std::is_trivially_copyable<T>::value, "SmallList copies its entries as bytes");

 public:
  static constexpr std::uint32_t kInline = N;

  SmallList() = default;
  SmallList(const SmallList& o) { assign(o.begin(), o.end()); }
  SmallList(SmallList&& o) noexcept { take(o); }
  SmallList& operator=(const SmallList& o) {
    if (this != &o) assign(o.begin(), o.end());
    return *this;
  }
  SmallList& operator=(SmallList&& o) noexcept {
    if (this != &o) {
      release();
      take(o);
    }
    return *this;
  }
  ~SmallList() { release(); }

  T* begin() { return data(); }
  T* end() { return data() + size_; }
  const T* begin() const { return data(); }
  const T* end() const { return data() + size_; }
  std::size_t size() const { return size_; }
  bool empty() const { return size_ == 0; }
  const T& operator[](std::size_t i) const { return data()[i]; }
  T& operator[](std::size_t i) { return data()[i]; }
  const T& front() const { return data()[0]; }
  const T& back() const { return data()[size_ - 1]; }

  void push_back(const T& v) {
    if (size_ == capacity_) reserve(2 * capacity_);
    data()[size_++] = v;
  }
  /// Empties the list, keeping its storage.
  void clear() { size_ = 0; }
  /// Removes [first, last) (the erase–remove idiom).
  T* erase(T* first, T* last) {
    std::copy(last, end(), first);
    size_ -= static_cast<std::uint32_t>(last - first);
    return first;
  }
  /// Replaces the entries with [first, last), in the storage it has when it fits.
  template <class It>
  void assign(It first, It last) {
    size_ = 0;
    reserve(static_cast<std::uint32_t>(std::distance(first, last)));
    for (; first != last; ++first) data()[size_++] = *first;
  }
  /// n entries: the first kept, new ones set to v.
  void resize(std::size_t n, const T& v = T()) {
    reserve(static_cast<std::uint32_t>(n));
    for (std::size_t i = size_; i < n; ++i) data()[i] = v;
    size_ = static_cast<std::uint32_t>(n);
  }
  std::vector<T> toVector() const { return std::vector<T>(begin(), end()); }

  friend bool operator==(const SmallList& a, const SmallList& b) {
    return a.size() == b.size() && std::equal(a.begin(), a.end(), b.begin());
  }
  friend bool operator!=(const SmallList& a, const SmallList& b) { return !(a == b); }
  friend bool operator==(const SmallList& a, const std::vector<T>& b) {
    return a.size() == b.size() && std::equal(a.begin(), a.end(), b.begin());
  }
  friend bool operator!=(const SmallList& a, const std::vector<T>& b) { return !(a == b); }

 private:
  bool onHeap() const { return capacity_ > N; }
  T* data() { return onHeap() ? heap_ : reinterpret_cast<T*>(inline_); }
  const T* data() const { return onHeap() ? heap_ : reinterpret_cast<const T*>(inline_); }
  void reserve(std::uint32_t capacity) {
    if (capacity <= capacity_) return;
    T* grown = static_cast<T*>(::operator new(sizeof(T) * capacity));
    std::memcpy(static_cast<void*>(grown), data(), sizeof(T) * size_);
    if (onHeap()) ::operator delete(heap_);
    heap_ = grown;
    capacity_ = capacity;
  }
  void release() {
    if (onHeap()) ::operator delete(heap_);
    capacity_ = N;
    size_ = 0;
  }
  // Takes o's entries (its heap block, or a copy of its inline ones); o is
  // left empty and inline.
  void take(SmallList& o) {
    size_ = o.size_;
    capacity_ = o.capacity_;
    if (o.onHeap()) heap_ = o.heap_;
    else std::memcpy(inline_, o.inline_, sizeof inline_);  // a fixed size: no library call
    o.capacity_ = N;
    o.size_ = 0;
  }

  std::uint32_t size_ = 0, capacity_ = N;
  union {
    alignas(T) unsigned char inline_[sizeof(T) * N];
    T* heap_;
  };
};

/// A clique's factor slots or children, a variable's factor slots.
using SmallIntList = SmallList<int, 4>;

}  // namespace gssm::internal
