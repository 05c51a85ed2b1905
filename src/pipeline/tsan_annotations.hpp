// ThreadSanitizer cannot see the synchronisation inside oneTBB when the library itself is not
// instrumented (Debian's is not), so every hand-over between TBB tasks would look like a race.
// BodyScope marks a task body: it acquires `token` when it starts and releases it when it ends,
// so bodies that ran one after the other are ordered as TBB orders them, while bodies that really
// overlapped stay unordered and a race between them is still reported. Without TSan these
// compile to nothing.
#pragma once

#if defined(__SANITIZE_THREAD__)
extern "C" void __tsan_acquire(void* addr);
extern "C" void __tsan_release(void* addr);
#endif

namespace roiflow::pipeline {

inline void tsan_acquire([[maybe_unused]] void* token) {
#if defined(__SANITIZE_THREAD__)
  __tsan_acquire(token);
#endif
}

inline void tsan_release([[maybe_unused]] void* token) {
#if defined(__SANITIZE_THREAD__)
  __tsan_release(token);
#endif
}

class BodyScope {
 public:
  explicit BodyScope(void* token) : token_(token) { tsan_acquire(token_); }
  ~BodyScope() { tsan_release(token_); }
  BodyScope(const BodyScope&) = delete;
  BodyScope& operator=(const BodyScope&) = delete;

 private:
  void* token_;
};

}  // namespace roiflow::pipeline
