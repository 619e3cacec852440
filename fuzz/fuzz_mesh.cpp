// SPDX-License-Identifier: GPL-3.0-or-later
// The mesh reader (a scenario's `mesh: {file: ...}`, a sequence's truth mesh; assimp underneath)
// on arbitrary bytes. The first byte picks the extension the file is given, which picks
// assimp's importer: PLY, OBJ or STL.
#include "fuzz_support.hpp"
#include "harness/formats/mesh_io.hpp"
#include "harness/support/errors.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  if (size == 0) return 0;
  static const char* const kExtensions[] = {".ply", ".obj", ".stl"};
  const std::string name = std::string("mesh") + kExtensions[data[0] % 3];
  const auto file = sonomap::fuzz::write_file(name, std::string(reinterpret_cast<const char*>(data + 1), size - 1));
  try {
    sonomap::harness::load_mesh(file);
  } catch (const sonomap::harness::InputError&) {
  }
  return 0;
}
