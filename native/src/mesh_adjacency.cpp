// Mesh adjacency: the flat arrays the snake reads in its inner loops (normals, areas,
// one-rings in CSR form, boundary flags, components), from the triangles and their
// face neighbours that intake made. No OpenMesh here.
#include <algorithm>
#include <cmath>
#include <limits>
#include <numeric>
#include <vector>

#include "relief_snake/mesh.hpp"

namespace relief_snake {

void Mesh::build_arrays() {
  const int nv = static_cast<int>(positions_.size());
  const int nf = static_cast<int>(face_vertices_.size() / 3);

  // face_neighbors_ comes from intake (edge k of f joins corners k+1 and k+2).

  // Face normals and areas; area-weighted vertex normals (sum of cross products).
  face_normals_.resize(nf);
  face_areas_.resize(nf);
  vertex_areas_.assign(nv, 0.0);
  vertex_normals_.assign(nv, Vec3::Zero());
  for (int f = 0; f < nf; ++f) {
    const int* c = &face_vertices_[3 * f];
    const Vec3 cross = (positions_[c[1]] - positions_[c[0]]).cross(positions_[c[2]] - positions_[c[0]]);
    const double norm = cross.norm();
    face_areas_[f] = 0.5 * norm;
    face_normals_[f] = norm > 0 ? Vec3(cross / norm) : Vec3(Vec3::UnitZ());
    for (int k = 0; k < 3; ++k) {
      vertex_normals_[c[k]] += cross;
      vertex_areas_[c[k]] += face_areas_[f] / 3.0;
    }
  }

  // One-ring faces (CSR).
  ring_face_offsets_.assign(nv + 1, 0);
  for (int c : face_vertices_) ++ring_face_offsets_[c + 1];
  for (int v = 0; v < nv; ++v) ring_face_offsets_[v + 1] += ring_face_offsets_[v];
  ring_faces_.resize(face_vertices_.size());
  {
    std::vector<std::size_t> fill(ring_face_offsets_.begin(), ring_face_offsets_.end() - 1);
    for (int f = 0; f < nf; ++f)
      for (int k = 0; k < 3; ++k) ring_faces_[fill[face_vertices_[3 * f + k]]++] = f;
  }

  for (int v = 0; v < nv; ++v) {
    const double norm = vertex_normals_[v].norm();
    if (norm > 0) {
      vertex_normals_[v] /= norm;
    } else {
      // Incident normals cancel (a fold): fall back to one incident face's normal.
      vertex_normals_[v] = face_normals_[ring_faces_[ring_face_offsets_[v]]];
    }
  }

  // Unique edges (each counted from the face with the smaller index, or once on
  // the boundary): one-ring vertices, boundary flags, average edge length.
  auto unique_edge = [&](int f, int k) {
    const int g = face_neighbors_[3 * f + k];
    return g < 0 || g > f;
  };
  ring_vertex_offsets_.assign(nv + 1, 0);
  boundary_vertex_.assign(nv, 0);
  std::size_t boundary_edges = 0, n_edges = 0;
  double edge_sum = 0;
  for (int f = 0; f < nf; ++f) {
    for (int k = 0; k < 3; ++k) {
      if (!unique_edge(f, k)) continue;
      const int a = face_vertices_[3 * f + (k + 1) % 3], b = face_vertices_[3 * f + (k + 2) % 3];
      ++ring_vertex_offsets_[a + 1];
      ++ring_vertex_offsets_[b + 1];
      ++n_edges;
      edge_sum += (positions_[a] - positions_[b]).norm();
      if (face_neighbors_[3 * f + k] < 0) {
        ++boundary_edges;
        boundary_vertex_[a] = boundary_vertex_[b] = 1;
      }
    }
  }
  for (int v = 0; v < nv; ++v) ring_vertex_offsets_[v + 1] += ring_vertex_offsets_[v];
  ring_vertices_.resize(ring_vertex_offsets_[nv]);
  {
    std::vector<std::size_t> fill(ring_vertex_offsets_.begin(), ring_vertex_offsets_.end() - 1);
    for (int f = 0; f < nf; ++f) {
      for (int k = 0; k < 3; ++k) {
        if (!unique_edge(f, k)) continue;
        const int a = face_vertices_[3 * f + (k + 1) % 3], b = face_vertices_[3 * f + (k + 2) % 3];
        ring_vertices_[fill[a]++] = b;
        ring_vertices_[fill[b]++] = a;
      }
    }
  }
  average_edge_length_ = n_edges ? edge_sum / static_cast<double>(n_edges) : 0;

  // Components: union-find over faces joined by an edge.
  std::vector<int> parent(nf);
  std::iota(parent.begin(), parent.end(), 0);
  auto find = [&](int x) {
    while (parent[x] != x) {
      parent[x] = parent[parent[x]];  // path halving
      x = parent[x];
    }
    return x;
  };
  for (int f = 0; f < nf; ++f)
    for (int k = 0; k < 3; ++k) {
      const int g = face_neighbors_[3 * f + k];
      if (g > f) {
        const int ra = find(f), rb = find(g);
        if (ra != rb) parent[std::max(ra, rb)] = std::min(ra, rb);
      }
    }
  std::vector<int> label(nf, -1);
  int n_components = 0;
  for (int f = 0; f < nf; ++f) {
    const int r = find(f);
    if (label[r] < 0) label[r] = n_components++;
    label[f] = label[r];
  }
  component_.resize(nv);
  for (int v = 0; v < nv; ++v) component_[v] = label[ring_faces_[ring_face_offsets_[v]]];

  // Bounding box diagonal.
  Vec3 lo = Vec3::Constant(std::numeric_limits<double>::infinity()), hi = -lo;
  for (const Vec3& p : positions_) {
    lo = lo.cwiseMin(p);
    hi = hi.cwiseMax(p);
  }
  bbox_diagonal_ = nv ? (hi - lo).norm() : 0;

  report_.triangles = static_cast<std::size_t>(nf);
  report_.components = static_cast<std::size_t>(n_components);
  report_.boundary_edges = boundary_edges;
}

}  // namespace relief_snake
