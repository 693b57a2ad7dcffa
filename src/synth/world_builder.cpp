#include "world_builder.hpp"

#include <algorithm>
#include <array>
#include <utility>

namespace kartograf::synth::detail {

namespace {

using Color = Eigen::Vector3d;

Color jitter(Rng& rng, const Color& base, double amount) {
  Color c = base;
  for (int i = 0; i < 3; ++i) c[i] += rng.uniform(-amount, amount);
  return c.cwiseMax(0.0).cwiseMin(1.0);
}

template <std::size_t N>
const Color& choose(Rng& rng, const std::array<Color, N>& palette) {
  return palette[static_cast<std::size_t>(rng.uniform_int(0, static_cast<int>(N) - 1))];
}

// The start of every textured recipe: `pattern` in `color` and that colour darkened by `shade`.
Material two_tone(const std::string& name, Pattern pattern, const Color& color, double shade) {
  Material m;
  m.name = name;
  m.pattern = pattern;
  m.color_a = color;
  m.color_b = (color * shade).cwiseMin(1.0);
  return m;
}

int add_material(World& world, Material material, Rng& rng) {
  material.seed = rng.bits();
  world.materials.push_back(std::move(material));
  return static_cast<int>(world.materials.size() - 1);
}

const std::array<Color, 7> kPaints = {Color(0.85, 0.82, 0.75), Color(0.62, 0.72, 0.84),
                                      Color(0.66, 0.78, 0.62), Color(0.88, 0.70, 0.58),
                                      Color(0.74, 0.68, 0.84), Color(0.74, 0.74, 0.72),
                                      Color(0.88, 0.83, 0.52)};
const std::array<Color, 3> kWoods = {Color(0.55, 0.38, 0.22), Color(0.68, 0.52, 0.33),
                                     Color(0.40, 0.26, 0.15)};

}  // namespace

int add_wall_material(World& world, Rng& rng, const std::string& name) {
  const Color paint = jitter(rng, choose(rng, kPaints), 0.04);
  Material m;
  if (rng.bernoulli(0.35)) {  // wallpaper
    m = two_tone(name, Pattern::stripes, paint, rng.uniform(0.72, 0.85));
    m.period = rng.uniform(0.15, 0.4);
    m.noise_amplitude = 0.04;
  } else {  // paint with a visible roller texture
    m = two_tone(name, Pattern::noise, paint, 0.82);
    m.noise_scale = rng.uniform(0.2, 0.4);
    m.noise_amplitude = 0.05;
  }
  return add_material(world, std::move(m), rng);
}

int add_floor_material(World& world, Rng& rng, const std::string& name, bool corridor) {
  const double choice = corridor ? 0.5 : rng.uniform();
  Material m;
  if (choice < 0.35) {  // wooden planks
    m = two_tone(name, Pattern::wood, jitter(rng, choose(rng, kWoods), 0.03), 0.75);
    m.period = rng.uniform(0.12, 0.2);
    m.noise_scale = 0.1;
    m.noise_amplitude = 0.06;
  } else if (choice < 0.75) {  // tiles
    const double light = rng.uniform(0.6, 0.8);
    const Color tile = jitter(rng, Color(light, light * 0.97, light * 0.9), 0.03);
    m = two_tone(name, Pattern::checker, tile, rng.uniform(0.6, 0.8));
    m.period = rng.uniform(0.3, 0.5);
    m.noise_amplitude = 0.05;
  } else {  // carpet
    m = two_tone(name, Pattern::noise, jitter(rng, choose(rng, kPaints) * 0.55, 0.05), 0.7);
    m.noise_scale = 0.04;
    m.noise_amplitude = 0.12;
  }
  return add_material(world, std::move(m), rng);
}

int add_ceiling_material(World& world, Rng& rng) {
  Material m;
  m.name = "ceiling";
  m.pattern = Pattern::noise;
  m.color_a = Color(0.9, 0.9, 0.88);
  m.color_b = Color(0.8, 0.8, 0.78);
  m.noise_scale = 0.5;
  m.noise_amplitude = 0.03;
  return add_material(world, std::move(m), rng);
}

int add_furniture_material(World& world, Rng& rng, const std::string& name, bool dark) {
  Material m;
  if (dark) {  // black lacquer / dark fabric: the IR sensor loses it
    m = two_tone(name, Pattern::noise, Color::Constant(rng.uniform(0.03, 0.06)), 0.7);
    m.noise_scale = 0.1;
    m.noise_amplitude = 0.1;
  } else if (rng.bernoulli(0.5)) {
    m = two_tone(name, Pattern::wood, jitter(rng, choose(rng, kWoods), 0.04), 0.7);
    m.period = rng.uniform(0.02, 0.05);
    m.noise_scale = 0.05;
  } else {
    const Color paint = jitter(rng, choose(rng, kPaints) * rng.uniform(0.6, 1.0), 0.05);
    m = two_tone(name, Pattern::noise, paint, 0.8);
    m.noise_scale = 0.08;
    m.noise_amplitude = 0.06;
  }
  return add_material(world, std::move(m), rng);
}

int add_door_material(World& world, Rng& rng, const std::string& name, bool dark) {
  const Color wood = dark ? Color(0.06, 0.045, 0.035) : jitter(rng, choose(rng, kWoods), 0.04);
  Material m = two_tone(name, Pattern::wood, wood, 0.75);
  m.period = rng.uniform(0.03, 0.06);
  m.noise_scale = 0.05;
  return add_material(world, std::move(m), rng);
}

std::vector<Eigen::Vector3d> face_rectangle(Face face, double level, const Eigen::Vector2d& lo,
                                            const Eigen::Vector2d& hi) {
  const int axis = face_axis(face);
  const int u = axis == 0 ? 1 : 0;
  const int v = axis == 2 ? 1 : 2;
  auto vertex = [&](double a, double b) {
    Eigen::Vector3d p;
    p[axis] = level;
    p[u] = a;
    p[v] = b;
    return p;
  };
  std::vector<Eigen::Vector3d> corners = {vertex(lo.x(), lo.y()), vertex(hi.x(), lo.y()),
                                          vertex(hi.x(), hi.y()), vertex(lo.x(), hi.y())};
  // That order turns counter-clockwise about e_u x e_v: +x, -y, +z for axes 0, 1, 2.
  const double natural = axis == 1 ? -1.0 : 1.0;
  if (natural != face_sign(face)) std::reverse(corners.begin(), corners.end());
  return corners;
}

Label add_plane(World& world, SemanticClass semantic, Face face, double level,
                std::vector<std::vector<Eigen::Vector3d>> polygons, Label room, int material,
                std::string name) {
  Plane plane;
  plane.id = static_cast<Label>(world.planes.size() + 1);
  plane.semantic = semantic;
  plane.normal = face_normal(face);
  plane.offset = -face_sign(face) * level;
  plane.polygons = std::move(polygons);
  plane.room = room;
  plane.material = material;
  plane.name = std::move(name);
  world.planes.push_back(std::move(plane));
  return world.planes.back().id;
}

int add_object_solid(World& world, const Box3& box, const std::array<bool, kFaceCount>& hidden,
                     SemanticClass semantic, Label room, int material, const std::string& name) {
  static const char* kFaceNames[kFaceCount] = {"-x", "+x", "-y", "+y", "-z", "+z"};
  Solid solid;
  solid.box = box;
  solid.kind = SolidKind::object;
  solid.material = material;
  for (int f = 0; f < kFaceCount; ++f) {
    if (hidden[f]) continue;
    const Face face = static_cast<Face>(f);
    const int axis = face_axis(face);
    const double level = face_sign(face) > 0 ? box.max[axis] : box.min[axis];
    Eigen::Vector2d lo, hi;
    int k = 0;
    for (int a = 0; a < 3; ++a) {
      if (a == axis) continue;
      lo[k] = box.min[a];
      hi[k] = box.max[a];
      ++k;
    }
    solid.face_planes[f] =
        add_plane(world, semantic, face, level, {face_rectangle(face, level, lo, hi)}, room,
                  material, name + " " + kFaceNames[f]);
  }
  world.solids.push_back(solid);
  return static_cast<int>(world.solids.size() - 1);
}

}  // namespace kartograf::synth::detail
