#pragma once
// A bounding-volume hierarchy of plane-fit moments over a mesh's faces (area
// moments) or vertices (unit point moments). Summing the moments of everything
// within a sphere then costs about the number of tree nodes the sphere's surface
// cuts, not the number of elements inside it: the planarity neighbourhood of
// radius h stays cheap however finely the scan samples that ball.
#include <cstddef>
#include <vector>

#include "relief_snake/mesh.hpp"
#include "relief_snake/plane_fit.hpp"

namespace relief_snake {

class MomentTree {
 public:
  /// Faces (area moments), vertices (unit points) or vertices weighted by their area
  /// (a third of the area of their faces).
  enum class Elements { Faces, Vertices, WeightedVertices };

  /// Builds the hierarchy over every face (or vertex) of the mesh: O(n log n).
  MomentTree(const Mesh& mesh, Elements elements);

  /// What a sphere query collects.
  struct Query {
    Vec3 center = Vec3::Zero();
    double radius = 0;
    int component = -1;           ///< only elements of this mesh component (-1: any)
    Vec3 facing = Vec3::Zero();   ///< only elements whose unit normal n has n . facing >= min_facing
    double min_facing = -1;       ///< -1 or a zero facing: no normal test
    double grain = 0;             ///< nodes with a box diagonal up to this are counted like faces, by their centroid
  };

  /// Moments, about query.center, of the elements inside the sphere. A face the
  /// sphere cuts counts whole if its centroid is inside (splitting cut faces into
  /// pieces changed no result we measured, and cost twice the time); so does a node
  /// no larger than query.grain. Thread-safe.
  PlaneMoments sphere(const Query& query) const;

  Elements elements() const { return elements_; }
  const Mesh& mesh() const { return mesh_; }
  std::size_t node_count() const { return nodes_.size(); }
  std::size_t memory_bytes() const;

 private:
  // The traversal fields first (one cache line), the sums after. Boxes and cones are
  // floats rounded outwards: looser, never tighter, so the sums stay exact.
  struct Node {
    float lo[3], hi[3];          // bounding box of the elements (whole faces)
    float axis[3];               // normal cone: every element normal n has n . axis >= cone_cos
    float cone_cos = -1, cone_sin = 0;
    int component = -1;          // the one component of all its elements, -1 if mixed
    int left = -1, right = -1;   // children; -1 for a leaf
    int begin = 0, end = 0;      // elements order_[begin, end)
    double weight = 0;           // moments about origin_ (PlaneMoments, the second moment's 6 entries)
    double first[3] = {0, 0, 0};
    double second[6] = {0, 0, 0, 0, 0, 0};  // xx yy zz xy xz yz
  };
  static void set_moments(Node& node, const PlaneMoments& m);
  static void add_moments(const Node& node, PlaneMoments* m);
  static void set_box(Node& node, const Vec3& lo, const Vec3& hi);
  static void set_cone(Node& node, const Vec3& axis, double cos_spread);
  int build(int begin, int end, const std::vector<unsigned>& codes);
  void finish_leaf(Node& node) const;
  void finish_inner(Node& node, const Node& a, const Node& b) const;
  PlaneMoments moments_of(const Node& node) const;
  void add_element(int e, const Query& q, double r2, PlaneMoments* out) const;
  void add_cut(const Vec3& a, const Vec3& b, const Vec3& c, const Query& q, double r2, PlaneMoments* out) const;
  Vec3 element_normal(int e) const;
  int element_component(int e) const;
  double element_weight(int e) const;  // vertices: 1 or their area

  const Mesh& mesh_;
  Elements elements_;
  Vec3 origin_ = Vec3::Zero();   // moments are taken about it (the mesh's bounding-box centre)
  std::vector<int> order_;       // elements in tree order
  std::vector<Node> nodes_;      // nodes_[0] is the root
};

}  // namespace relief_snake
