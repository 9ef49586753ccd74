// Memory back to the system after a large request (after one, the segmentation node
// stayed at 264 MB and the executor at 829 MB while idle). glibc keeps freed heap pages for
// reuse; malloc_trim(0) returns the free ones, so an idle node shrinks back to its working set.
#pragma once

namespace lfd {

/// Returns the heap's free pages to the system (glibc malloc_trim); cheap next to a request.
void trimHeap();

/// Trims the heap when it goes out of scope: declared first in a request's handler, it runs after
/// every other local of the handler has been freed.
class TrimHeapOnExit {
 public:
  TrimHeapOnExit() = default;
  TrimHeapOnExit(const TrimHeapOnExit&) = delete;
  TrimHeapOnExit& operator=(const TrimHeapOnExit&) = delete;
  ~TrimHeapOnExit() { trimHeap(); }
};

}  // namespace lfd
