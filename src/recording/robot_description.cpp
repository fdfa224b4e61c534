#include "omnivert/recording/robot_description.hpp"

#include <tinyxml2.h>

#include <algorithm>
#include <cmath>
#include <sstream>

#include "omnivert/core/angles.hpp"
#include "omnivert/core/error.hpp"

namespace omnivert::recording {

void FrameTree::add(const FrameTransform& t) { parent_of_[t.child] = t; }

std::vector<std::string> FrameTree::chain(const std::string& frame) const {
  std::vector<std::string> c = {frame};
  for (auto it = parent_of_.find(frame); it != parent_of_.end();
       it = parent_of_.find(it->second.parent)) {
    if (std::find(c.begin(), c.end(), it->second.parent) != c.end()) break;  // a loop
    c.push_back(it->second.parent);
  }
  return c;
}

std::optional<Eigen::Isometry3d> FrameTree::transform(const std::string& from,
                                                      const std::string& to,
                                                      std::string* why) const {
  auto known = [&](const std::string& f) {
    if (parent_of_.count(f)) return true;
    return std::any_of(parent_of_.begin(), parent_of_.end(), [&](const auto& kv) {
      return kv.second.parent == f;
    });
  };
  for (const std::string& f : {from, to}) {
    if (!known(f)) {
      if (why) *why = "no frame '" + f + "' (frames: " + frames() + ")";
      return std::nullopt;
    }
  }
  const std::vector<std::string> a = chain(from), b = chain(to);
  // The nearest common ancestor: the first of b's chain that is in a's.
  std::size_t ib = 0, ia = 0;
  for (; ib < b.size(); ++ib) {
    const auto it = std::find(a.begin(), a.end(), b[ib]);
    if (it != a.end()) {
      ia = static_cast<std::size_t>(it - a.begin());
      break;
    }
  }
  if (ib == b.size()) {
    if (why) *why = "frames '" + from + "' and '" + to + "' are not connected";
    return std::nullopt;
  }
  // T_ancestor_x = T_ancestor_c1 ... T_ck_x along each chain.
  auto up = [&](const std::vector<std::string>& c, std::size_t n) {
    Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
    for (std::size_t k = 0; k < n; ++k) T = parent_of_.at(c[k]).T_parent_child * T;
    return T;
  };
  return up(a, ia).inverse() * up(b, ib);
}

std::string FrameTree::frames() const {
  std::vector<std::string> names;
  for (const auto& [child, t] : parent_of_) {
    names.push_back(child);
    names.push_back(t.parent);
  }
  std::sort(names.begin(), names.end());
  names.erase(std::unique(names.begin(), names.end()), names.end());
  std::string s;
  for (const std::string& n : names) s += (s.empty() ? "" : ", ") + n;
  return s;
}

namespace {

Eigen::Vector3d triple(const char* text, const std::string& what, const std::string& field) {
  Eigen::Vector3d v = Eigen::Vector3d::Zero();
  if (!text) return v;
  std::istringstream in(text);
  if (!(in >> v(0) >> v(1) >> v(2)) || !v.allFinite())
    throw InputError(what + ": " + field + "=\"" + text + "\" is not three numbers");
  return v;
}

}  // namespace

Urdf parse_urdf(const std::string& xml, const std::string& what) {
  tinyxml2::XMLDocument doc;
  if (doc.Parse(xml.c_str(), xml.size()) != tinyxml2::XML_SUCCESS)
    throw InputError(what + ": the URDF does not parse (" + std::string(doc.ErrorStr()) + ")");
  const tinyxml2::XMLElement* robot = doc.FirstChildElement("robot");
  if (!robot) throw InputError(what + ": the URDF has no <robot> element");
  Urdf u;
  for (auto* j = robot->FirstChildElement("joint"); j; j = j->NextSiblingElement("joint")) {
    const char* name = j->Attribute("name");
    const auto* parent = j->FirstChildElement("parent");
    const auto* child = j->FirstChildElement("child");
    const char* p = parent ? parent->Attribute("link") : nullptr;
    const char* c = child ? child->Attribute("link") : nullptr;
    if (!name || !p || !c) {
      throw InputError(what + ": a URDF joint without a name, a parent or a child link (line " +
                       std::to_string(j->GetLineNum()) + ")");
    }
    FrameTransform t{p, c, Eigen::Isometry3d::Identity()};
    if (const auto* o = j->FirstChildElement("origin")) {
      const std::string at = std::string("joint ") + name + " <origin> ";
      const Eigen::Vector3d xyz = triple(o->Attribute("xyz"), what, at + "xyz");
      const Eigen::Vector3d rpy = triple(o->Attribute("rpy"), what, at + "rpy");
      t.T_parent_child.linear() = (Eigen::AngleAxisd(rpy(2), Eigen::Vector3d::UnitZ()) *
                                   Eigen::AngleAxisd(rpy(1), Eigen::Vector3d::UnitY()) *
                                   Eigen::AngleAxisd(rpy(0), Eigen::Vector3d::UnitX()))
                                      .toRotationMatrix();
      t.T_parent_child.translation() = xyz;
    }
    u.tree.add(t);
    u.joint_child[name] = c;
  }
  for (auto* l = robot->FirstChildElement("link"); l; l = l->NextSiblingElement("link")) {
    const char* name = l->Attribute("name");
    if (!name) continue;
    for (const char* kind : {"collision", "visual"}) {
      const auto* g = l->FirstChildElement(kind);
      const auto* geo = g ? g->FirstChildElement("geometry") : nullptr;
      const auto* cyl = geo ? geo->FirstChildElement("cylinder") : nullptr;
      double r = 0;
      if (cyl && cyl->QueryDoubleAttribute("radius", &r) == tinyxml2::XML_SUCCESS && r > 0) {
        u.cylinder_radius[name] = r;
        break;
      }
    }
  }
  return u;
}

UrdfWheels urdf_wheels(const Urdf& urdf,
                       const std::string& left_joint,
                       const std::string& right_joint,
                       const std::string& what) {
  auto child = [&](const std::string& joint) {
    const auto it = urdf.joint_child.find(joint);
    if (it == urdf.joint_child.end())
      throw InputError(what + ": the URDF has no joint '" + joint + "'");
    return it->second;
  };
  const std::string l = child(left_joint), r = child(right_joint);
  std::string why;
  const auto T = urdf.tree.transform(l, r, &why);
  if (!T) throw InputError(what + ": the URDF's wheel links: " + why);
  UrdfWheels w;
  w.wheel_base = T->translation().norm();
  std::vector<double> radii;
  for (const std::string& link : {l, r})
    if (const auto it = urdf.cylinder_radius.find(link); it != urdf.cylinder_radius.end())
      radii.push_back(it->second);
  if (!radii.empty()) {
    double sum = 0;
    for (double x : radii) sum += x;
    w.wheel_radius = sum / static_cast<double>(radii.size());
  }
  return w;
}

CameraMount camera_mount(const Eigen::Isometry3d& T) {
  CameraMount m;
  const Eigen::Vector3d p = T.translation();
  const Eigen::Matrix3d R = T.linear();
  m.rho = std::hypot(p(0), p(1));
  m.phi = m.rho > 0 ? std::atan2(p(1), p(0)) : 0.0;
  m.height = p(2);
  const double yaw = std::atan2(R(1, 0), R(0, 0));  // the camera x axis on the base's plane
  m.psi = wrap_angle(yaw - m.phi);
  m.tilt = std::acos(std::clamp(R(2, 2), -1.0, 1.0));
  return m;
}

}  // namespace omnivert::recording
