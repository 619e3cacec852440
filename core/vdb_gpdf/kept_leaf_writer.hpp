// SPDX-License-Identifier: GPL-3.0-or-later
#pragma once

#include "core/marching_cubes.hpp"

#include <openvdb/openvdb.h>

namespace sonomap::gpdf {

// Serial writes to a grid, voxel by voxel, where a write mostly lands in the leaf of the write
// before (a source's votes lie along its ray, a local leaf's cells in one or two global
// leaves): that leaf and its values are kept. Through the accessor, a count took two walks of
// its cache (to read the value, then to set it) and each value read checked whether the
// leaf's buffer is loaded.
template <class GridT>
class KeptLeafWriter {
 public:
  explicit KeptLeafWriter(GridT& grid) : acc_(grid.getAccessor()) {}
  // Voxel v's value (the background's if v was not written before), v marked active.
  typename GridT::ValueType& on(const openvdb::Coord& v) {
    if (leaf_ == nullptr || leaf_origin_of(v) != leaf_->origin()) fetch(v);
    const openvdb::Index i = Leaf::coordToOffset(v);
    leaf_->setValueOn(i);
    return values_[i];
  }

 private:
  // The rare change of leaf, kept out of line so that on() stays small enough to inline in the
  // loops that count (a call per vote cost about a tenth of the counting).
  __attribute__((noinline)) void fetch(const openvdb::Coord& v) {
    leaf_ = acc_.touchLeaf(v);
    values_ = leaf_->buffer().data();
  }

  using Leaf = typename GridT::TreeType::LeafNodeType;
  static_assert(Leaf::DIM == kLeafDim, "leaf_origin_of finds the grid's leaves");
  typename GridT::Accessor acc_;
  Leaf* leaf_ = nullptr;
  typename GridT::ValueType* values_ = nullptr;
};

}  // namespace sonomap::gpdf
