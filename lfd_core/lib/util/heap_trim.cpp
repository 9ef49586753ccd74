#include "lfd_core/util/heap_trim.hpp"

#include <malloc.h>

namespace lfd {

void trimHeap() {
  ::malloc_trim(0);
}

}  // namespace lfd
