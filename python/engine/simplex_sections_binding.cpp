#include "python/engine/simplex_sections_binding.hpp"

#include <cstdint>
#include <mutex>
#include <string_view>
#include <utility>

#include <pybind11/numpy.h>

#include "proto/sections/simplex_sections.hpp"
#include "python/engine/engine_error.hpp"

namespace py = pybind11;

namespace galpha::python {

namespace {

// One reader a Classify stream: its zstd context and scratch buffer are reused from chunk to
// chunk. The mutex makes a reader shared between threads slow, not wrong (the decode runs with the
// GIL released).
class SectionReaderObject {
 public:
  py::tuple Read(int arity, uint64_t count, bool zstd, const py::buffer& data, uint64_t chunk_index) {
    // Refused here before the outputs are sized; the reader checks both again.
    if (arity < 1 || arity > 3 || count == 0 || count > wire::kMaxSimplicesPerEncodedChunk) {
      ThrowIfError(reader_.Read(arity, count, zstd, {}, chunk_index, nullptr, nullptr));
    }
    const py::buffer_info view = data.request();
    if (view.ndim != 1 || view.itemsize != 1 || (view.strides.size() == 1 && view.strides[0] != 1)) {
      throw py::value_error("SimplexSectionReader.read: data must be contiguous bytes");
    }
    const std::string_view bytes(static_cast<const char*>(view.ptr), static_cast<size_t>(view.size));
    py::array_t<uint32_t> indices(static_cast<py::ssize_t>(count * static_cast<uint64_t>(arity)));
    py::array_t<uint8_t> classes(static_cast<py::ssize_t>(count));
    uint32_t* index_out = indices.mutable_data();
    char* class_out = reinterpret_cast<char*>(classes.mutable_data());
    absl::Status read;
    {
      py::gil_scoped_release release;
      std::lock_guard<std::mutex> lock(mutex_);
      read = reader_.Read(arity, count, zstd, bytes, chunk_index, index_out, class_out);
    }
    ThrowIfError(read);
    return py::make_tuple(std::move(indices), std::move(classes));
  }

 private:
  std::mutex mutex_;
  wire::SimplexSectionReader reader_;
};

}  // namespace

void RegisterSimplexSectionReader(py::module_& module) {
  py::class_<SectionReaderObject>(module, "SimplexSectionReader",
                                  "Decodes the data of compact Classify chunks (EncodedSimplexChunk.data); one "
                                  "a stream, reusing its buffers.")
      .def(py::init<>())
      .def("read", &SectionReaderObject::Read, py::arg("arity"), py::arg("count"), py::arg("zstd"), py::arg("data"),
           py::arg("chunk_index"),
           "(indices: uint32 array of arity * count, classes: uint8 array of count) from the chunk's data "
           "(zstd: one zstd frame), with the GIL released; EngineError (INVALID_ARGUMENT, naming the chunk) for "
           "everything the proto says a client refuses.");
}

}  // namespace galpha::python
