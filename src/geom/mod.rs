//! Geometry: regions, lattices, triangle meshes, primitive wall shapes (in progress).
