// An independent, exact validator of galpha::Triangulation, for tests.
//
// It re-derives everything the engine promises from the points alone, with the exact predicates of
// core/exact/predicates.hpp and none of the engine's code: the representatives of duplicates, a
// counter-clockwise manifold triangulation whose boundary is the convex hull (collinear hull points
// included, as in CGAL), the edge ownership layout of the report "Computing 2D Alpha Shapes Using GPU"
// (section 3.1), Euler's relation, and the Delaunay property under Simulation of Simplicity on input
// indices.
#pragma once

#include "absl/status/status.h"
#include "gpu/triangulation/delaunay.hpp"

namespace galpha {

/// Checks every invariant of `t`, O(n log n). Returns OK, FailedPrecondition when the arrays are
/// malformed (sizes disagree, indices out of range), or Internal naming the first violated property
/// and the triangle, edge or point that violates it. The properties, in the order checked:
/// - representative[i] is the first input index holding a point equal to points[i]; num_unique
///   counts the distinct points;
/// - without triangles (0-2 distinct points or all collinear): the distinct points are collinear and
///   the edges join them consecutively in lexicographic order, i.e. in order along their line;
/// - with triangles: every triangle has three distinct representative vertices and is strictly
///   counter-clockwise (exact orientation); neighbours are symmetric across the same two vertices;
///   no directed edge occurs twice; the triangles are edge-connected; the edge list follows the
///   ownership rule with tri_edge_begin the exclusive scan of owned counts and no edge twice; every
///   distinct point is a vertex; V - E + F == 1; the boundary edges form one counter-clockwise
///   cycle equal to the exact convex hull with collinear boundary points kept; and no neighbour's
///   opposite vertex lies inside a triangle's circumcircle (InCircleSoS, input indices as ids).
absl::Status CheckTriangulation(const Triangulation& t);

}  // namespace galpha
