#pragma once
// Contact geometries with closed-form pairings, shared by the contact-model and
// support-row tests: slave nodes above a flat master line, and slave nodes around a
// master arc (a regular polygon inscribed in a circle).
#include <Eigen/Dense>
#include <cmath>
#include <vector>

#include <contactrom/fom/contact_model.hpp>

namespace contactrom::test {

/// Node coordinates and the chains of one contact pair.
struct ContactGeometry {
  Eigen::Matrix2Xd nodes;
  fom::ContactPairChains chains;
};

/// Slave nodes (ids 0 … |slave_x|−1) at height `height` above the master line y = 0
/// whose nodes sit at x = 0, 1, …, `segments` (ids after the slaves). The master body
/// lies below the line: its chain runs from right to left (body on the left), so
/// the outward normal is (0, 1) and master segment j spans x ∈ [segments − j − 1,
/// segments − j].
inline ContactGeometry flat_master(const std::vector<double>& slave_x, double height, int segments) {
  ContactGeometry g;
  const int ns = static_cast<int>(slave_x.size());
  g.nodes.resize(2, ns + segments + 1);
  for (int k = 0; k < ns; ++k) {
    g.nodes.col(k) = Eigen::Vector2d(slave_x[static_cast<size_t>(k)], height);
    g.chains.slave.push_back(k);
  }
  for (int j = 0; j <= segments; ++j) {
    g.nodes.col(ns + j) = Eigen::Vector2d(segments - j, 0.0);
    g.chains.master.push_back(ns + j);
  }
  return g;
}

/// Master arc: `segments` chords of the unit circle from angle 0 to π, counter-
/// clockwise (the disk on the left, outward normals radial); slave nodes at radius
/// `radius` and the given angles (ids 0 … |angles|−1, master node ids after them).
inline ContactGeometry circular_master(const std::vector<double>& angles, double radius, int segments) {
  ContactGeometry g;
  const int ns = static_cast<int>(angles.size());
  g.nodes.resize(2, ns + segments + 1);
  for (int k = 0; k < ns; ++k) {
    const double a = angles[static_cast<size_t>(k)];
    g.nodes.col(k) = radius * Eigen::Vector2d(std::cos(a), std::sin(a));
    g.chains.slave.push_back(k);
  }
  for (int j = 0; j <= segments; ++j) {
    const double a = M_PI * j / segments;
    g.nodes.col(ns + j) = Eigen::Vector2d(std::cos(a), std::sin(a));
    g.chains.master.push_back(ns + j);
  }
  return g;
}

/// Full displacement of a motion x ↦ x + t of every node, on the surface dofs of `model`.
inline Eigen::VectorXd surface_motion(const fom::ContactModel& model, const Eigen::Matrix2Xd& displacement_per_node) {
  const std::vector<int>& dofs = model.surface_dofs();
  Eigen::VectorXd u(static_cast<Eigen::Index>(dofs.size()));
  for (size_t i = 0; i < dofs.size(); ++i) u(static_cast<Eigen::Index>(i)) = displacement_per_node(dofs[i] % 2, dofs[i] / 2);
  return u;
}

}  // namespace contactrom::test
