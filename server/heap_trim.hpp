// Giving the heap a build freed back to the system, off the path of the answer that waits for it.
//
// A build frees hundreds of bytes a point at once and glibc keeps them for reuse, so without a trim
// the process would sit at its peak forever. But malloc_trim walks every arena and returns free
// pages one madvise at a time: 13-41 ms after each 1M-point build on the 2-core machine, which the
// Build answer used to wait for. One background thread trims instead; requests that arrive while
// it works are merged into one more pass.
#pragma once

namespace galpha::server {

/// Asks for freed heap memory to be given back to the system (glibc's malloc_trim) on the trimmer
/// thread, soon; returns at once. Cheap enough to call after every release of a family.
void ReturnFreedHeapMemory();

/// Blocks until every trim requested before this call has run (for tests that measure the
/// process).
void WaitForHeapTrims();

}  // namespace galpha::server
