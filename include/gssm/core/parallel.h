#pragma once
// Independent jobs on a few threads: the dataset processor's methods, the
// figures of a run. Each job's error is kept (not thrown across threads), so
// the caller decides which to report once every job was tried.
#include <algorithm>
#include <atomic>
#include <cstddef>
#include <exception>
#include <thread>
#include <vector>

namespace gssm {

/// Calls job(k) for k = 0 … count − 1, in that order of starting, on up to
/// `threads` threads (the calling thread is one of them); returns each
/// job's exception (null where it returned).
template <class Job>
std::vector<std::exception_ptr> runJobs(std::size_t count, std::size_t threads, Job&& job) {
  std::vector<std::exception_ptr> errors(count);
  std::atomic<std::size_t> next{0};
  auto work = [&] {
    for (std::size_t k; (k = next++) < count;) {
      try {
        job(k);
      } catch (...) {
        errors[k] = std::current_exception();
      }
    }
  };
  std::vector<std::thread> pool;
  for (std::size_t t = 1; t < std::min(std::max<std::size_t>(threads, 1), count); ++t) pool.emplace_back(work);
  work();
  for (auto& t : pool) t.join();
  return errors;
}

}  // namespace gssm
