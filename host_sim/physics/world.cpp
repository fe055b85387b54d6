// SPDX-License-Identifier: MIT
// The pouring world: a rotating bucket on a revolute joint, a target bucket on the ground, circles of
// liquid. Box2D angles are counter-clockwise; θ is clockwise (toward the target on the right), so the
// sign flips at every crossing between the two.
#include <box2d/box2d.h>

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <cstring>
#include <mutex>
#include <new>
#include <vector>

#include "poursim/poursim.h"
#include "poursim_internal.hpp"
#include "world.hpp"

namespace {

std::once_flag g_units_once;
// Box2D keeps its worlds in one global table; creating and destroying them is not thread-safe.
std::mutex g_world_table;

// Walls bounce at 0.1 and circles at 0.5 only if the pair takes the smaller of the two.
float restitution_min(float a, int, float b, int) { return a < b ? a : b; }

constexpr double kWorldHalfWidth = 1.5; // the floor's extent; side walls stop anything rolling off
constexpr double kWorldHeight = 3.0;
constexpr uint64_t kLiquidCategory = 0x2;
constexpr double kGravity = 9.81;     // [m/s²]
constexpr double kRunawaySpeed = 50.0; // [m/s]: no particle of a pour gets near this; beyond it the step failed

// Signed distance from p to an axis-aligned box (negative inside).
double box_sdf(const Eigen::Vector2d &p, const Eigen::Vector2d &lo, const Eigen::Vector2d &hi) {
  Eigen::Vector2d c = 0.5 * (lo + hi), h = 0.5 * (hi - lo);
  Eigen::Vector2d d = (p - c).cwiseAbs() - h;
  return d.cwiseMax(0.0).norm() + std::min(std::max(d.x(), d.y()), 0.0);
}

// Folds whole 64-bit words into the trajectory hash: FNV's prime, then a shift so the high bits reach the
// low ones. A word at a time (not FNV-1a's byte at a time) keeps the hash off the step's critical path.
inline uint64_t hash_words(uint64_t h, const void *data, size_t n_words) {
  const unsigned char *p = static_cast<const unsigned char *>(data);
  for (size_t i = 0; i < n_words; ++i) {
    uint64_t x;
    std::memcpy(&x, p + 8 * i, sizeof x);
    h = (h ^ x) * 1099511628211ULL;
    h ^= h >> 29;
  }
  return h;
}

} // namespace

namespace poursim {

// The three boxes of a bucket in its own frame (origin at the bucket's centre).
void bucket_walls(const poursim_config_t &c, Eigen::Vector2d lo[3], Eigen::Vector2d hi[3]) {
  double wi = 0.5 * c.bucket_inner_width, w = c.bucket_wall, hh = 0.5 * c.bucket_height;
  lo[0] = {-wi - w, -hh}, hi[0] = {wi + w, -hh + w}; // bottom
  lo[1] = {-wi - w, -hh}, hi[1] = {-wi, hh};         // left wall
  lo[2] = {wi, -hh}, hi[2] = {wi + w, hh};           // right wall
}

} // namespace poursim

using poursim::set_error;

static void build_scene(poursim_world_t *w, uint32_t seed) {
  const poursim_config_t &c = w->ep;
  b2WorldDef wd = b2DefaultWorldDef();
  wd.gravity = {0.0f, static_cast<float>(-kGravity)};
  wd.restitutionThreshold = static_cast<float>(c.restitution_threshold);
  wd.contactHertz = static_cast<float>(c.contact_hertz);
  wd.restitutionCallback = restitution_min;
  wd.enableSleep = c.fluid == 0; // the fluid layer moves every particle every step
  {
    std::lock_guard<std::mutex> lock(g_world_table);
    w->world = b2CreateWorld(&wd);
  }
  w->has_world = true;

  b2SurfaceMaterial wall_mat = b2DefaultSurfaceMaterial();
  wall_mat.friction = static_cast<float>(c.friction);
  wall_mat.restitution = static_cast<float>(c.restitution_wall);

  // Ground, the target bucket standing on it, and walls that close the world.
  b2BodyDef gd = b2DefaultBodyDef();
  w->ground = b2CreateBody(w->world, &gd);
  b2ShapeDef sd = b2DefaultShapeDef();
  sd.material = wall_mat;
  sd.enableContactEvents = false; // nothing reads Box2D's events: they would only cost time
  const float W = static_cast<float>(kWorldHalfWidth), Hw = static_cast<float>(kWorldHeight);
  b2Polygon floor = b2MakeOffsetBox(W + 0.1f, 0.1f, {0.0f, -0.1f}, b2Rot_identity);
  b2CreatePolygonShape(w->ground, &sd, &floor);
  b2Polygon left = b2MakeOffsetBox(0.1f, 0.5f * Hw, {-W - 0.1f, 0.5f * Hw}, b2Rot_identity);
  b2Polygon right = b2MakeOffsetBox(0.1f, 0.5f * Hw, {W + 0.1f, 0.5f * Hw}, b2Rot_identity);
  b2Polygon roof = b2MakeOffsetBox(W + 0.1f, 0.1f, {0.0f, Hw + 0.1f}, b2Rot_identity);
  b2CreatePolygonShape(w->ground, &sd, &left);
  b2CreatePolygonShape(w->ground, &sd, &right);
  b2CreatePolygonShape(w->ground, &sd, &roof);
  Eigen::Vector2d lo[3], hi[3];
  poursim::bucket_walls(c, lo, hi);
  Eigen::Vector2d target_centre(c.target_dx, 0.5 * c.bucket_height);
  // The target bucket stands on its load cell: a static body of its own, so its contacts are its load.
  w->target = b2CreateBody(w->world, &gd);
  for (int i = 0; i < 3; ++i) {
    Eigen::Vector2d mid = 0.5 * (lo[i] + hi[i]) + target_centre, half = 0.5 * (hi[i] - lo[i]);
    b2Polygon box = b2MakeOffsetBox(static_cast<float>(half.x()), static_cast<float>(half.y()),
                                    {static_cast<float>(mid.x()), static_cast<float>(mid.y())}, b2Rot_identity);
    w->target_shapes[i] = b2CreatePolygonShape(w->target, &sd, &box);
  }

  // The rotating bucket: a dynamic body whose origin is the pivot (the bucket's centre).
  b2BodyDef bd = b2DefaultBodyDef();
  bd.type = b2_dynamicBody;
  bd.position = {0.0f, static_cast<float>(c.pivot_height)};
  w->bucket = b2CreateBody(w->world, &bd);
  double wall_area = 0.0;
  for (int i = 0; i < 3; ++i) wall_area += (hi[i] - lo[i]).prod();
  b2ShapeDef bsd = b2DefaultShapeDef();
  bsd.material = wall_mat;
  bsd.enableContactEvents = false;
  bsd.density = static_cast<float>(c.bucket_mass / wall_area);
  for (int i = 0; i < 3; ++i) {
    Eigen::Vector2d mid = 0.5 * (lo[i] + hi[i]), half = 0.5 * (hi[i] - lo[i]);
    b2Polygon box = b2MakeOffsetBox(static_cast<float>(half.x()), static_cast<float>(half.y()),
                                    {static_cast<float>(mid.x()), static_cast<float>(mid.y())}, b2Rot_identity);
    b2CreatePolygonShape(w->bucket, &bsd, &box);
  }
  // The motor's rotor turns N times as fast as the bucket: its inertia counts N² times at the output.
  b2MassData md = b2Body_GetMassData(w->bucket);
  w->bucket_mass_kg = md.mass;
  md.rotationalInertia += static_cast<float>(poursim::reflected_inertia(c));
  b2Body_SetMassData(w->bucket, md);
  b2RevoluteJointDef jd = b2DefaultRevoluteJointDef();
  jd.bodyIdA = w->ground;
  jd.bodyIdB = w->bucket;
  jd.localAnchorA = {0.0f, static_cast<float>(c.pivot_height)};
  jd.localAnchorB = {0.0f, 0.0f};
  jd.enableLimit = true;
  jd.lowerAngle = static_cast<float>(-c.theta_max);
  jd.upperAngle = static_cast<float>(-c.theta_min);
  jd.enableMotor = true; // holds the bucket upright while the liquid settles
  jd.motorSpeed = 0.0f;
  jd.maxMotorTorque = 1e4f;
  w->joint = b2CreateRevoluteJoint(w->world, &jd);

  // Liquid: a jittered lattice of the rest spacing filling the bucket from the bottom; the seed moves
  // every circle by up to 10 % of the lattice step, so no two seeds pour alike.
  const int n = c.n_particles;
  const double s = poursim::particle_spacing(&c), r = poursim::particle_radius(&c);
  const int cols = std::max(1, static_cast<int>(std::floor(c.bucket_inner_width / s)));
  const double dx = c.bucket_inner_width / cols;
  // A rigid pile cannot start compressed; a fluid starts at its rest spacing (area s² a particle).
  const double dy = c.fluid ? s * s / dx : std::max(s * s / dx, 2.0 * r + 1e-3);
  const double bottom = c.pivot_height - 0.5 * c.bucket_height + c.bucket_wall;
  poursim::Rng rng(0x5eedULL ^ (static_cast<unsigned long long>(seed) << 20));
  b2SurfaceMaterial liquid_mat = b2DefaultSurfaceMaterial();
  liquid_mat.friction = static_cast<float>(c.friction);
  liquid_mat.restitution = static_cast<float>(c.restitution_liquid);
  const double density = poursim::liquid_mass(&c) / (n * M_PI * r * r);
  w->circles.assign(static_cast<size_t>(n), b2BodyId{});
  w->radii.assign(static_cast<size_t>(n), static_cast<float>(r));
  for (int k = 0; k < n; ++k) {
    double jx = (rng.uniform() - 0.5) * 0.2 * dx, jy = (rng.uniform() - 0.5) * 0.2 * dy;
    b2BodyDef cd = b2DefaultBodyDef();
    cd.type = b2_dynamicBody;
    cd.position = {static_cast<float>(-0.5 * c.bucket_inner_width + (k % cols + 0.5) * dx + jx),
                   static_cast<float>(bottom + (k / cols + 0.5) * dy + jy)};
    b2BodyId body = b2CreateBody(w->world, &cd);
    b2ShapeDef csd = b2DefaultShapeDef();
    csd.material = liquid_mat;
    csd.enableContactEvents = false;
    csd.density = static_cast<float>(density);
    // With the fluid layer on, circles meet each other only through it.
    csd.filter.categoryBits = kLiquidCategory;
    if (c.fluid) csd.filter.maskBits = ~kLiquidCategory;
    b2Circle circle = {{0.0f, 0.0f}, static_cast<float>(r)};
    b2CreateCircleShape(body, &csd, &circle);
    w->circles[static_cast<size_t>(k)] = body;
  }
  poursim::FluidParams fp;
  fp.h = c.fluid_smoothing * s;
  fp.rho0 = poursim::fluid_rest_density(s, fp.h);
  fp.k = c.fluid_stiffness;
  fp.sigma = c.fluid_viscosity;
  fp.agitation = c.fluid_agitation;
  w->fluid.configure(fp, n, 0xF1D5EEDULL ^ (static_cast<uint64_t>(seed) << 17));
  for (std::vector<double> *v : {&w->fx, &w->fy, &w->fvx, &w->fvy}) v->assign(static_cast<size_t>(n), 0.0);
}

static void destroy_scene(poursim_world_t *w) {
  if (!w->has_world) return;
  std::lock_guard<std::mutex> lock(g_world_table);
  b2DestroyWorld(w->world);
  w->has_world = false;
}

// Positions, regions, volumes, normalised observation, reward; updates the hash and wall penetration.
static void measure(poursim_world_t *w) {
  const poursim_config_t &c = w->ep;
  poursim_obs_t &o = w->obs;
  size_t n = w->circles.size();
  b2Transform xf = b2Body_GetTransform(w->bucket);
  Eigen::Vector2d pivot(xf.p.x, xf.p.y);
  // World → bucket frame: undo the bucket's counter-clockwise rotation.
  const Eigen::Matrix2d to_bucket = Eigen::Rotation2Dd(-static_cast<double>(b2Rot_GetAngle(xf.q))).toRotationMatrix();
  double wi = 0.5 * c.bucket_inner_width, hh = 0.5 * c.bucket_height;
  double tx0 = c.target_dx - wi, tx1 = c.target_dx + wi, rim = c.bucket_height;
  const Eigen::Vector2d target_centre(c.target_dx, 0.5 * c.bucket_height);
  Eigen::Vector2d lo[3], hi[3];
  poursim::bucket_walls(c, lo, hi);
  int counts[4] = {0, 0, 0, 0};
  uint64_t h = w->hash;
  for (size_t i = 0; i < n; ++i) {
    const b2Vec2 p = {static_cast<float>(w->fx[i]), static_cast<float>(w->fy[i])}; // Box2D's floats, exactly
    static_assert(sizeof p == sizeof(uint64_t), "a position is one word");
    h = hash_words(h, &p, 1);
    const double px = p.x, py = p.y;
    Eigen::Vector2d local = to_bucket * (Eigen::Vector2d(px, py) - pivot);
    uint8_t region;
    if (std::fabs(local.x()) <= wi && local.y() >= -hh + c.bucket_wall && local.y() <= hh)
      region = 0;
    else if (px >= tx0 && px <= tx1 && py >= c.bucket_wall && py <= rim)
      region = 1;
    else if (py < rim)
      region = 2;
    else
      region = 3;
    w->region[i] = region;
    counts[region]++;
    // How deep any circle sinks into a wall of either bucket (more than its radius = passed through).
    const Eigen::Vector2d in_target = Eigen::Vector2d(px, py) - target_centre;
    for (const Eigen::Vector2d &q : {local, in_target}) {
      // Only a circle within reach of a wall can sink into it.
      if (std::fabs(q.x()) < wi - 2.0 * static_cast<double>(w->radii[i]) && std::fabs(q.y()) < hh - 2.0 * c.bucket_wall - 2.0 * static_cast<double>(w->radii[i])) continue;
      if (q.norm() > hh + wi + 0.05) continue;
      for (int k = 0; k < 3; ++k) {
        double pen = static_cast<double>(w->radii[i]) - box_sdf(q, lo[k], hi[k]);
        if (pen > w->max_wall_pen) w->max_wall_pen = pen;
      }
    }
  }
  double inv = n > 0 ? 1.0 / static_cast<double>(n) : 0.0;
  o.step = w->step;
  o.t = w->step * c.dt;
  o.theta = -static_cast<double>(b2RevoluteJoint_GetAngle(w->joint));
  o.omega = -static_cast<double>(b2Body_GetAngularVelocity(w->bucket));
  o.v_rotating = counts[0] * inv;
  o.v_target = counts[1] * inv;
  o.v_spill = counts[2] * inv;
  o.v_flight = counts[3] * inv;
  o.done = (o.t >= c.episode_s - 0.5 * c.dt) ? 1 : 0;
  // Physics only: the sensors' noise, lag and rate leave the hash as it is (docs/simulator.md).
  double scalars[8] = {o.theta, o.omega, o.v_rotating, o.v_target, o.v_spill, o.v_flight, o.torque, o.motor_torque};
  w->hash = hash_words(h, scalars, sizeof scalars / sizeof(uint64_t));
}

// The loads on the two cells now [g]. The rotating bucket hangs on its pivot, which stands on a load
// cell: the cell carries the joint's reaction (the bucket and whatever the liquid does to it, weight and
// inertia alike), tared by the empty bucket's weight. The target bucket stands on the other: it carries
// every contact force on the target body, so liquid landing in it weighs its momentum too (ṁ·v).
static void cell_loads(poursim_world_t *w, double *rotating_g, double *target_g) {
  const double to_g = 1000.0 / kGravity;
  const b2Vec2 f = b2Joint_GetConstraintForce(w->joint); // on the bucket (body B), over the last sub-step
  *rotating_g = static_cast<double>(f.y) * to_g - 1000.0 * w->bucket_mass_kg;
  const int cap = b2Body_GetContactCapacity(w->target);
  if (static_cast<size_t>(cap) > w->contacts.size()) w->contacts.resize(static_cast<size_t>(cap));
  const int n = b2Body_GetContactData(w->target, w->contacts.data(), cap);
  double fy = 0.0; // on the target [N·s over a sub-step]
  for (int k = 0; k < n; ++k) {
    const b2ContactData &cd = w->contacts[static_cast<size_t>(k)];
    const b2Manifold &m = cd.manifold;
    // The solver pushes shape B along +normal (and +tangent = right perpendicular) and A the other way.
    const bool target_is_a = B2_ID_EQUALS(cd.shapeIdA, w->target_shapes[0]) ||
                             B2_ID_EQUALS(cd.shapeIdA, w->target_shapes[1]) ||
                             B2_ID_EQUALS(cd.shapeIdA, w->target_shapes[2]);
    const double normal_y = m.normal.y, tangent_y = -static_cast<double>(m.normal.x);
    double py = 0.0;
    for (int j = 0; j < m.pointCount; ++j)
      py += static_cast<double>(m.points[j].normalImpulse) * normal_y +
            static_cast<double>(m.points[j].tangentImpulse) * tangent_y;
    fy += target_is_a ? -py : py;
  }
  const double inv_h = w->ep.substeps / w->ep.dt;
  *target_g = -fy * inv_h * to_g; // pushed down = a positive load
}

// The sensors after a step (or, with initial, at reset: the liquid has rested on both cells since before
// the delay reaches back).
static void sense(poursim_world_t *w, bool initial) {
  poursim_obs_t &o = w->obs;
  o.encoder = poursim::encoder_count(o.theta, w->ep.encoder_bits);
  double rot_g, tgt_g;
  cell_loads(w, &rot_g, &tgt_g);
  if (initial) {
    w->scale_rotating.reset(w->ep, rot_g, w->sensor_noise);
    w->scale_target.reset(w->ep, tgt_g, w->sensor_noise);
  } else {
    w->scale_rotating.update(w->step, rot_g, w->sensor_noise);
    w->scale_target.update(w->step, tgt_g, w->sensor_noise);
  }
  o.scale_rotating_g = w->scale_rotating.reading();
  o.scale_target_g = w->scale_target.reading();
  const poursim::FocDrive *foc = w->drive.foc();
  o.drive_faults = foc != nullptr ? foc->telemetry().faults : 0u;
  o.drive_trusted = foc == nullptr || foc->running() ? 1 : 0;
}

// The drive's Coulomb friction (and the brake when engaged) as the joint's motor held at zero speed: it
// stops the axis against up to that torque, and slips at exactly that torque beyond.
static void set_joint_friction(poursim_world_t *w) {
  const double hold = w->ep.friction_coulomb + (w->brake ? w->ep.brake_torque : 0.0);
  b2RevoluteJoint_EnableMotor(w->joint, hold > 0.0);
  b2RevoluteJoint_SetMotorSpeed(w->joint, 0.0f);
  b2RevoluteJoint_SetMaxMotorTorque(w->joint, static_cast<float>(hold));
}

// The circles' positions and velocities, read from Box2D once a step (after it moved them) for the fluid
// layer, the numerics check and the measurements.
static void read_circles(poursim_world_t *w) {
  for (size_t i = 0; i < w->circles.size(); ++i) {
    const b2Vec2 p = b2Body_GetPosition(w->circles[i]), v = b2Body_GetLinearVelocity(w->circles[i]);
    w->fx[i] = p.x, w->fy[i] = p.y, w->fvx[i] = v.x, w->fvy[i] = v.y;
  }
}

// One dt: the fluid layer changes the circles' velocities, then Box2D moves everything and resolves the
// contacts with the buckets.
static void advance(poursim_world_t *w) {
  const poursim_config_t &c = w->ep;
  if (c.fluid && !w->circles.empty()) {
    w->fluid.step(c.dt, -kGravity, w->fx.data(), w->fy.data(), w->fvx.data(), w->fvy.data());
    for (size_t i = 0; i < w->circles.size(); ++i)
      b2Body_SetLinearVelocity(w->circles[i], {static_cast<float>(w->fvx[i]), static_cast<float>(w->fvy[i])});
  }
  b2World_Step(w->world, static_cast<float>(c.dt), c.substeps);
  read_circles(w);
}

// A liquid that blew up shows as a particle that is not finite, has left the world, or moves faster
// than anything in a pour can; found at the step where it happens, never carried on.
static int check_numerics(poursim_world_t *w) {
  for (size_t i = 0; i < w->circles.size(); ++i) {
    const double px = w->fx[i], py = w->fy[i], vx = w->fvx[i], vy = w->fvy[i];
    bool inside = std::fabs(px) <= kWorldHalfWidth + 0.5 && py >= -0.5 && py <= kWorldHeight + 0.5;
    const double speed2 = vx * vx + vy * vy; // NaN fails the comparison below
    if (!std::isfinite(px) || !std::isfinite(py) || !inside || !(speed2 <= kRunawaySpeed * kRunawaySpeed)) {
      const double speed = std::sqrt(speed2);
      std::snprintf(w->error, sizeof w->error,
                    "step %u: the liquid blew up: particle %zu at (%g, %g) m moving at %g m/s (fluid_stiffness or dt "
                    "too large for the particle spacing?)",
                    w->step, i, px, py, speed);
      destroy_scene(w);
      return POURSIM_ENUMERIC;
    }
  }
  return POURSIM_OK;
}

namespace poursim {

void empty_bucket(poursim_world_t *w, bool free_spin) {
  if (!w->has_world) return;
  for (b2BodyId b : w->circles) b2DestroyBody(b);
  w->circles.clear();
  w->radii.clear();
  for (std::vector<double> *v : {&w->fx, &w->fy, &w->fvx, &w->fvy}) v->clear();
  w->region.clear();
  if (free_spin) b2RevoluteJoint_EnableLimit(w->joint, false);
}

} // namespace poursim

namespace poursim {

poursim_world_t *create_unset(const poursim_config_t *config, char *err, size_t err_len) {
  if (poursim_config_validate(config, err, err_len) != POURSIM_OK) return nullptr;
  // Box2D's length unit is global: 0.1 (decimetre-scale tolerances) suits circles of ~1 cm.
  std::call_once(g_units_once, [] { b2SetLengthUnitsPerMeter(0.1f); });
  poursim_world_t *w = new (std::nothrow) poursim_world_t();
  if (w == nullptr) {
    set_error(err, err_len, POURSIM_EINVAL, "out of memory");
    return nullptr;
  }
  w->cfg = *config;
  w->ep = *config;
  return w;
}

} // namespace poursim

extern "C" {

poursim_world_t *poursim_create(const poursim_config_t *config, char *err, size_t err_len) {
  poursim_world_t *w = poursim::create_unset(config, err, err_len);
  if (w == nullptr) return nullptr;
  int rc = poursim_reset(w, config->seed);
  if (rc != POURSIM_OK) {
    set_error(err, err_len, rc, "while the liquid settled: %s", w->error);
    poursim_destroy(w);
    return nullptr;
  }
  return w;
}

int poursim_reset(poursim_world_t *w, uint32_t seed) {
  if (w == nullptr) return POURSIM_EINVAL;
  destroy_scene(w);
  w->ep = poursim::draw_episode_config(w->cfg, seed);
  build_scene(w, seed);
  const poursim_config_t &c = w->ep;
  w->drive.reset(c, seed);
  w->sensor_noise = poursim::Gauss(0x5E4507ULL ^ (static_cast<uint64_t>(seed) << 28));
  size_t n = w->circles.size();
  w->region.assign(n, 0);
  read_circles(w);
  // Settle with the bucket held by the joint motor, then release it at rest.
  int settle_steps = static_cast<int>(std::lround(c.settle_s / c.dt));
  w->step = 0;
  w->brake = false;
  w->error[0] = '\0';
  for (int i = 0; i < settle_steps; ++i) advance(w);
  int rc = check_numerics(w);
  if (rc != POURSIM_OK) return rc;
  set_joint_friction(w);
  b2Body_SetAngularVelocity(w->bucket, 0.0f);
  w->hash = 14695981039346656037ULL;
  w->max_wall_pen = 0.0;
  std::memset(&w->obs, 0, sizeof w->obs);
  measure(w);
  sense(w, true);
  w->max_wall_pen = 0.0; // count excursions from t = 0 on
  return POURSIM_OK;
}

int poursim_step(poursim_world_t *w, double action, poursim_obs_t *out) {
  if (w == nullptr || !w->has_world) return POURSIM_EINVAL;
  if (!std::isfinite(action)) return POURSIM_EINVAL;
  const double a = std::max(-1.0, std::min(1.0, action));
  const double tau_cmd = a * w->ep.tau_max;
  // The drive delivers the command of command_latency_ticks steps ago, within its torque–speed
  // envelope at the speed the step starts from; viscous friction opposes that speed (explicit: b·dt/J is
  // ~1e-4). Coulomb friction and the brake are the joint's motor.
  const double omega = -static_cast<double>(b2Body_GetAngularVelocity(w->bucket));
  const double tau_motor = w->drive.step(tau_cmd, omega);
  if (w->drive.brake_requested()) w->brake = true; // a drive fault: the bucket ends held, never coasting
  set_joint_friction(w);
  b2Body_ApplyTorque(w->bucket, static_cast<float>(-(tau_motor - w->ep.friction_viscous * omega)), true);
  advance(w);
  w->step++;
  int rc = check_numerics(w);
  if (rc != POURSIM_OK) return rc;
  w->obs.torque = tau_cmd;
  w->obs.motor_torque = tau_motor;
  measure(w);
  sense(w, false);
  if (out != nullptr) *out = w->obs;
  return POURSIM_OK;
}

int poursim_step_servo(poursim_world_t *w, double theta_ref, poursim_obs_t *out) {
  if (w == nullptr || !w->has_world) return POURSIM_EINVAL;
  if (!std::isfinite(theta_ref)) return POURSIM_EINVAL;
  // The motor reaches the speed that closes the error in one step, with torque to spare.
  b2RevoluteJoint_EnableMotor(w->joint, true);
  b2RevoluteJoint_SetMaxMotorTorque(w->joint, 1e4f);
  b2RevoluteJoint_SetMotorSpeed(w->joint, static_cast<float>(-(theta_ref - w->obs.theta) / w->ep.dt));
  advance(w);
  w->step++;
  int rc = check_numerics(w);
  if (rc != POURSIM_OK) return rc;
  w->obs.torque = -static_cast<double>(b2RevoluteJoint_GetMotorTorque(w->joint));
  w->obs.motor_torque = w->obs.torque;
  measure(w);
  sense(w, false);
  if (out != nullptr) *out = w->obs;
  return POURSIM_OK;
}

int poursim_set_brake(poursim_world_t *w, int engaged) {
  if (w == nullptr || !w->has_world) return POURSIM_EINVAL;
  w->brake = engaged != 0;
  return POURSIM_OK;
}

const char *poursim_world_error(const poursim_world_t *w) { return w ? w->error : "world is NULL"; }

double poursim_max_density_ratio(const poursim_world_t *w) {
  return w != nullptr && w->ep.fluid ? w->fluid.max_density_ratio() : 0.0;
}

void poursim_observe(const poursim_world_t *w, poursim_obs_t *out) {
  if (w != nullptr && out != nullptr) *out = w->obs;
}

void poursim_destroy(poursim_world_t *w) {
  if (w == nullptr) return;
  destroy_scene(w);
  delete w;
}

const poursim_config_t *poursim_world_config(const poursim_world_t *w) { return w ? &w->cfg : nullptr; }

const poursim_config_t *poursim_episode_config(const poursim_world_t *w) { return w ? &w->ep : nullptr; }

int poursim_particle_count(const poursim_world_t *w) { return w ? static_cast<int>(w->circles.size()) : 0; }

int poursim_particles(const poursim_world_t *w, float *xy, float *radius, int capacity) {
  if (w == nullptr || capacity < 0) return 0;
  int n = std::min(capacity, static_cast<int>(w->circles.size()));
  for (int i = 0; i < n; ++i) {
    size_t k = static_cast<size_t>(i);
    if (xy != nullptr) {
      xy[2 * k] = static_cast<float>(w->fx[k]);
      xy[2 * k + 1] = static_cast<float>(w->fy[k]);
    }
    if (radius != nullptr) radius[k] = w->radii[k];
  }
  return n;
}

int poursim_particle_regions(const poursim_world_t *w, uint8_t *region, int capacity) {
  if (w == nullptr || region == nullptr || capacity < 0) return 0;
  int n = std::min(capacity, static_cast<int>(w->circles.size()));
  for (int i = 0; i < n; ++i) region[i] = w->region[static_cast<size_t>(i)];
  return n;
}

double poursim_max_overlap(const poursim_world_t *w) {
  if (w == nullptr) return 0.0;
  const poursim_config_t &c = w->ep;
  size_t n = w->circles.size();
  double worst = 0.0;
  // Circles of the fluid meet through pressure, not contact: only the pile's circle pairs overlap.
  for (size_t i = 0; i < n && !c.fluid; ++i) {
    Eigen::Vector2d pi(w->fx[i], w->fy[i]);
    for (size_t j = i + 1; j < n; ++j) {
      Eigen::Vector2d pj(w->fx[j], w->fy[j]);
      double ov = static_cast<double>(w->radii[i] + w->radii[j]) - (pi - pj).norm();
      worst = std::max(worst, ov);
    }
  }
  b2Transform xf = b2Body_GetTransform(w->bucket);
  Eigen::Vector2d pivot(xf.p.x, xf.p.y), target_centre(c.target_dx, 0.5 * c.bucket_height);
  const Eigen::Matrix2d to_bucket = Eigen::Rotation2Dd(-static_cast<double>(b2Rot_GetAngle(xf.q))).toRotationMatrix();
  Eigen::Vector2d lo[3], hi[3];
  poursim::bucket_walls(c, lo, hi);
  for (size_t i = 0; i < n; ++i) {
    Eigen::Vector2d p(w->fx[i], w->fy[i]);
    Eigen::Vector2d local = to_bucket * (p - pivot), in_target = p - target_centre;
    double r = w->radii[i];
    for (int k = 0; k < 3; ++k) {
      worst = std::max(worst, r - box_sdf(local, lo[k], hi[k]));
      worst = std::max(worst, r - box_sdf(in_target, lo[k], hi[k]));
    }
    worst = std::max(worst, r - p.y()); // the floor
  }
  return worst;
}

double poursim_max_wall_penetration(const poursim_world_t *w) { return w ? w->max_wall_pen : 0.0; }

uint64_t poursim_trajectory_hash(const poursim_world_t *w) { return w ? w->hash : 0; }

const char *poursim_version(void) { return "poursim 0.1.0 (Box2D 3.1)"; }

} // extern "C"

int poursim_drive_telemetry(const poursim_world_t *w, poursim_drive_telemetry_t *out) {
  if (w == nullptr || out == nullptr) return POURSIM_EINVAL;
  *out = poursim_drive_telemetry_t{};
  if (const poursim::FocDrive *f = w->drive.foc()) {
    const poursim::FocTelemetry &t = f->telemetry();
    *out = {t.peak_current, t.peak_vbus, t.min_vbus, t.faults, t.limits};
  }
  return POURSIM_OK;
}
