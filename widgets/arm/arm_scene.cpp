#include "widgets/arm/arm_scene.h"

#include <vtkActor.h>
#include <vtkCamera.h>
#include <vtkCellArray.h>
#include <vtkConeSource.h>
#include <vtkCubeSource.h>
#include <vtkCylinderSource.h>
#include <vtkDoubleArray.h>
#include <vtkLight.h>
#include <vtkLookupTable.h>
#include <vtkPlaneSource.h>
#include <vtkPointData.h>
#include <vtkPoints.h>
#include <vtkPolyData.h>
#include <vtkPolyDataMapper.h>
#include <vtkProperty.h>
#include <vtkRenderer.h>
#include <vtkSMPTools.h>
#include <vtkSphereSource.h>
#include <vtkTransform.h>
#include <vtkTubeFilter.h>

#include <algorithm>
#include <array>
#include <cmath>

namespace flexarm {
namespace {

constexpr double kRadToDeg = 57.29577951308232;
constexpr double kHighlight[3] = {0.95, 0.08, 0.08};
// Where the parts sit (metres, axis one is z; loosely an IRB 1400): the gearbox input ring on
// the fixed foot, the gear spring above it, the gearbox output drum, the arm spring, and the
// arm's turret with the shoulder at 0.475 m.
constexpr double kMotorX = 0.0, kMotorY = -0.36;
constexpr double kGearSpringZ0 = 0.16, kGearSpringZ1 = 0.28, kGearSpringR = 0.17;
constexpr double kArmSpringZ0 = 0.36, kArmSpringZ1 = 0.44, kArmSpringR = 0.15;
constexpr double kParallelZ = 0.32, kParallelR0 = 0.2, kParallelR1 = 0.27;
constexpr int kCageBars = 16, kParallelSpokes = 6;
constexpr double kTraceDrop = 0.4;  // the oldest point of the trace lies this far below the tip

vtkSmartPointer<vtkActor> makeActor(vtkAlgorithm* source, const double rgb[3]) {
  auto mapper = vtkSmartPointer<vtkPolyDataMapper>::New();
  mapper->SetInputConnection(source->GetOutputPort());
  auto actor = vtkSmartPointer<vtkActor>::New();
  actor->SetMapper(mapper);
  actor->GetProperty()->SetColor(rgb[0], rgb[1], rgb[2]);
  actor->GetProperty()->SetAmbient(0.25);
  actor->GetProperty()->SetDiffuse(0.85);
  actor->GetProperty()->SetSpecular(0.3);
  actor->GetProperty()->SetSpecularPower(20);
  return actor;
}

vtkSmartPointer<vtkTransform> childOf(vtkTransform* parent) {
  // Operations added to the child act in the parent's frame (VTK's default pre-multiply).
  auto t = vtkSmartPointer<vtkTransform>::New();
  t->SetInput(parent);
  return t;
}

// A vertical cylinder of radius r between heights z0 and z1 (VTK's cylinders lie along y).
vtkSmartPointer<vtkCylinderSource> cylinder(double r, double z0, double z1, double x = 0,
                                            double y = 0) {
  auto c = vtkSmartPointer<vtkCylinderSource>::New();
  c->SetRadius(r);
  c->SetHeight(z1 - z0);
  c->SetResolution(48);
  c->SetCenter(x, 0.5 * (z0 + z1), -y);  // turned upright below: (x, y, z) -> (x, -z, y)
  return c;
}

vtkSmartPointer<vtkCubeSource> box(double lx, double ly, double lz, double cx, double cy,
                                   double cz) {
  auto b = vtkSmartPointer<vtkCubeSource>::New();
  b->SetXLength(lx);
  b->SetYLength(ly);
  b->SetZLength(lz);
  b->SetCenter(cx, cy, cz);
  return b;
}

double clampUnit(double x) { return std::clamp(x, -1.0, 1.0); }

}  // namespace

// One rigid part turning about axis one: its actors share the part's transform.
struct ArmScene::Body {
  ArmPart part;
  std::vector<vtkSmartPointer<vtkActor>> actors;
  std::vector<std::array<double, 3>> colours;  // each actor's own paint
};

// A spring drawn as bars between two circles (axial: one above the other; radial: spokes
// between two radii at one height); the bars' twist is the drawn deflection.
struct ArmScene::Cage {
  ArmPart part;
  bool radial = false;
  double r0 = 0, r1 = 0, z0 = 0, z1 = 0, fromDeg = 0, toDeg = 360;
  int bars = kCageBars;
  double deflection = 0.0;
  vtkSmartPointer<vtkPoints> points;
  vtkSmartPointer<vtkDoubleArray> scalars;
  vtkSmartPointer<vtkPolyData> lines;
  vtkSmartPointer<vtkTubeFilter> tubes;
  double radius = 0.0;  // of a bar's tube, m
  vtkSmartPointer<vtkActor> actor;
};

ArmScene::ArmScene()
    : renderer_(vtkSmartPointer<vtkRenderer>::New()),
      lut_(vtkSmartPointer<vtkLookupTable>::New()),
      rotor_(vtkSmartPointer<vtkTransform>::New()),
      gearInput_(vtkSmartPointer<vtkTransform>::New()),
      gearOutput_(vtkSmartPointer<vtkTransform>::New()),
      arm_(vtkSmartPointer<vtkTransform>::New()),
      parallel_(vtkSmartPointer<vtkTransform>::New()),
      ghost_(vtkSmartPointer<vtkTransform>::New()) {
  // The scene's arrays are small: VTK's threaded loops (the tubes, the ranges of the colour
  // scalars) cost more in starting their thread pool every frame, which asks the system how
  // many processors it has each time, than they save.
  static const bool sequential = vtkSMPTools::SetBackend("Sequential");
  (void)sequential;
  build();
  setSprings(0);
  setDeflectionRange(maxDeflection_);
  updateTransforms();
  resetCamera();
}

ArmScene::~ArmScene() = default;

vtkRenderer* ArmScene::renderer() const { return renderer_; }

ArmScene::Body& ArmScene::body(ArmPart part) {
  for (Body& b : bodies_)
    if (b.part == part) return b;
  bodies_.push_back(Body{part, {}, {}});
  return bodies_.back();
}

void ArmScene::build() {
  renderer_->SetBackground(0.16, 0.18, 0.22);
  renderer_->SetBackground2(0.42, 0.46, 0.52);
  renderer_->GradientBackgroundOn();

  const double floorGrey[3] = {0.55, 0.57, 0.6};
  auto floor = vtkSmartPointer<vtkPlaneSource>::New();
  floor->SetOrigin(-1.2, -1.2, 0.0);
  floor->SetPoint1(1.2, -1.2, 0.0);
  floor->SetPoint2(-1.2, 1.2, 0.0);
  floor->SetResolution(12, 12);
  auto floorActor = makeActor(floor, floorGrey);
  floorActor->GetProperty()->SetRepresentationToWireframe();
  renderer_->AddActor(floorActor);

  // Each part: a source, its paint, the transform it hangs on (local placement after it).
  auto upright = [](vtkTransform* parent) {
    auto t = childOf(parent);
    t->RotateX(90);  // VTK cylinders lie along y
    return t;
  };
  auto add = [this](ArmPart part, vtkAlgorithm* source, std::array<double, 3> rgb,
                    vtkTransform* placement) {
    auto actor = makeActor(source, rgb.data());
    actor->SetUserTransform(placement);
    renderer_->AddActor(actor);
    Body& b = body(part);
    b.actors.push_back(actor);
    b.colours.push_back(rgb);
    return actor;
  };
  auto fixed = vtkSmartPointer<vtkTransform>::New();
  const std::array<double, 3> dark = {0.25, 0.25, 0.28}, white = {0.92, 0.92, 0.9},
                              steel = {0.45, 0.55, 0.68}, orange = {0.93, 0.45, 0.1},
                              amber = {0.95, 0.55, 0.15}, bronze = {0.72, 0.42, 0.16},
                              blue = {0.2, 0.6, 0.85}, violet = {0.55, 0.4, 0.75};

  // Foot (fixed), with the motor housing beside it: the motor's body is fixed, its rotor
  // turns by phi_m about its own vertical axis.
  auto foot = cylinder(0.28, 0.0, 0.12);
  auto footActor = makeActor(foot, dark.data());
  footActor->SetUserTransform(upright(fixed));
  renderer_->AddActor(footActor);
  add(ArmPart::Motor, cylinder(0.07, 0.0, 0.14, kMotorX, kMotorY), dark, upright(fixed));
  rotor_->Identity();
  add(ArmPart::Motor, cylinder(0.065, 0.14, 0.165, kMotorX, kMotorY), {0.3, 0.3, 0.36},
      upright(rotor_));
  add(ArmPart::Motor, box(0.05, 0.016, 0.012, kMotorX + 0.03, kMotorY, 0.171), white,
      childOf(rotor_));

  // Gearbox input ring (r phi_m) with marks on its rim.
  add(ArmPart::GearInput, cylinder(0.24, 0.12, 0.16), steel, upright(gearInput_));
  for (int i = 0; i < 4; ++i) {
    auto t = childOf(gearInput_);
    t->RotateZ(90.0 * i);
    add(ArmPart::GearInput, box(0.04, 0.03, 0.042, 0.235, 0, 0.14), white, t);
  }
  // Gearbox output drum (phi_g).
  add(ArmPart::GearOutput, cylinder(0.2, kGearSpringZ1, kArmSpringZ0), bronze,
      upright(gearOutput_));
  for (int i = 0; i < 4; ++i) {
    auto t = childOf(gearOutput_);
    t->RotateZ(45.0 + 90.0 * i);
    add(ArmPart::GearOutput, box(0.03, 0.03, 0.082, 0.198, 0, 0.5 * (kGearSpringZ1 + kArmSpringZ0)),
        white, t);
  }
  // Parallel mass (phi_p, four-mass): a counterweight behind the drum.
  add(ArmPart::ParallelMass, box(0.1, 0.22, 0.1, -0.31, 0, kParallelZ), violet, childOf(parallel_));

  // The arm (phi_a) and its rigid ghost (r phi_m), the same shapes.
  auto armShapes = [&](vtkTransform* root, bool ghost) {
    std::vector<std::pair<vtkSmartPointer<vtkAlgorithm>, vtkSmartPointer<vtkTransform>>> parts;
    std::vector<std::array<double, 3>> paint;
    if (!ghost) {  // the turret: the ghost shows the links and the tool
      parts.emplace_back(cylinder(0.18, kArmSpringZ1, 0.5), upright(root));
      paint.push_back(orange);
    }
    auto shoulder = vtkSmartPointer<vtkSphereSource>::New();
    shoulder->SetRadius(0.13);
    shoulder->SetThetaResolution(32);
    shoulder->SetPhiResolution(16);
    shoulder->SetCenter(0.15, 0, 0.475);
    if (!ghost) {  // the ghost needs no joint
      parts.emplace_back(shoulder, childOf(root));
      paint.push_back({0.3, 0.3, 0.33});
    }
    auto lower = childOf(root);
    lower->Translate(0.15, 0, 0.475);
    lower->RotateY(10);
    parts.emplace_back(box(0.14, 0.16, 0.6, 0, 0, 0.3), lower);
    paint.push_back(orange);
    auto upper = childOf(lower);
    upper->Translate(0, 0, 0.6);
    upper->RotateY(-10);
    parts.emplace_back(box(0.72, 0.12, 0.12, 0.3, 0, 0), upper);
    paint.push_back(amber);
    auto toolT = childOf(upper);
    toolT->Translate(0.66, 0, -0.14);
    auto tool = vtkSmartPointer<vtkConeSource>::New();
    tool->SetHeight(0.18);
    tool->SetRadius(0.06);
    tool->SetResolution(32);
    tool->SetDirection(0, 0, -1);
    parts.emplace_back(tool, toolT);
    paint.push_back(blue);
    if (!ghost) {
      toolT->Update();
      toolT->TransformPoint(std::array<double, 3>{0, 0, -0.09}.data(), tip_);
    }
    for (std::size_t i = 0; i < parts.size(); ++i) {
      if (!ghost) {
        add(ArmPart::Arm, parts[i].first, paint[i], parts[i].second);
        continue;
      }
      // Drawn as edges, not as a translucent surface: on a software renderer translucency
      // costs extra passes over the whole picture every frame.
      const double grey[3] = {0.7, 0.9, 1.0};
      auto actor = makeActor(parts[i].first, grey);
      actor->SetUserTransform(parts[i].second);
      actor->GetProperty()->SetRepresentationToWireframe();
      actor->GetProperty()->SetLighting(false);
      actor->GetProperty()->SetSpecular(0.0);
      renderer_->AddActor(actor);
      ghostActors_.push_back(actor);
    }
  };
  arm_->Identity();
  armShapes(arm_, false);
  // The ghost is drawn a little larger, so that it wraps the arm where they coincide.
  auto ghostRoot = childOf(ghost_);
  ghostRoot->Translate(0, 0, 0.75);
  ghostRoot->Scale(1.03, 1.03, 1.03);
  ghostRoot->Translate(0, 0, -0.75);
  armShapes(ghostRoot, true);

  // Solid sleeves where the model has no spring: the whole column turns together.
  auto sleeve = [&](vtkTransform* on, double r, double z0, double z1) {
    auto a = makeActor(cylinder(r, z0, z1), steel.data());
    a->SetUserTransform(upright(on));
    renderer_->AddActor(a);
    sleeves_.push_back(a);
  };
  sleeve(gearInput_, kGearSpringR, kGearSpringZ0, kGearSpringZ1);
  sleeve(gearOutput_, kArmSpringR, kArmSpringZ0, kArmSpringZ1);

  // The springs, coloured by their deflection.
  auto cage = [&](ArmPart part, bool radial, double r0, double r1, double z0, double z1,
                  int bars, double fromDeg, double toDeg) {
    Cage c;
    c.part = part;
    c.radial = radial;
    c.r0 = r0;
    c.r1 = r1;
    c.z0 = z0;
    c.z1 = z1;
    c.bars = bars;
    c.fromDeg = fromDeg;
    c.toDeg = toDeg;
    c.points = vtkSmartPointer<vtkPoints>::New();
    c.points->SetNumberOfPoints(2 * bars);
    c.scalars = vtkSmartPointer<vtkDoubleArray>::New();
    c.scalars->SetNumberOfTuples(2 * bars);
    auto cells = vtkSmartPointer<vtkCellArray>::New();
    for (int i = 0; i < bars; ++i) {
      const vtkIdType ids[2] = {2 * i, 2 * i + 1};
      cells->InsertNextCell(2, ids);
    }
    c.lines = vtkSmartPointer<vtkPolyData>::New();
    c.lines->SetPoints(c.points);
    c.lines->SetLines(cells);
    c.lines->GetPointData()->SetScalars(c.scalars);
    c.radius = radial ? 0.007 : 0.009;
    c.tubes = vtkSmartPointer<vtkTubeFilter>::New();
    c.tubes->SetInputData(c.lines);
    c.tubes->SetRadius(c.radius);
    c.tubes->SetNumberOfSides(8);
    auto mapper = vtkSmartPointer<vtkPolyDataMapper>::New();
    mapper->SetInputConnection(c.tubes->GetOutputPort());
    mapper->SetLookupTable(lut_);
    mapper->UseLookupTableScalarRangeOn();
    c.actor = vtkSmartPointer<vtkActor>::New();
    c.actor->SetMapper(mapper);
    c.actor->GetProperty()->SetAmbient(0.35);
    c.actor->GetProperty()->SetDiffuse(0.75);
    renderer_->AddActor(c.actor);
    cages_.push_back(c);
  };
  cage(ArmPart::GearSpring, false, kGearSpringR, kGearSpringR, kGearSpringZ0, kGearSpringZ1,
       kCageBars, 0, 360);
  cage(ArmPart::ArmSpring, false, kArmSpringR, kArmSpringR, kArmSpringZ0, kArmSpringZ1,
       kCageBars, 0, 360);
  cage(ArmPart::ParallelSpring, true, kParallelR0, kParallelR1, kParallelZ, kParallelZ,
       kParallelSpokes, 150, 210);

  // The tool tip's trace and the ghost tip's.
  for (auto* trace : {&tipTrace_, &ghostTrace_}) {
    *trace = vtkSmartPointer<vtkPolyData>::New();
    (*trace)->SetPoints(vtkSmartPointer<vtkPoints>::New());
    (*trace)->SetLines(vtkSmartPointer<vtkCellArray>::New());
  }
  auto traceActor = [&](vtkPolyData* data, const double rgb[3], double radius) {
    auto tubes = vtkSmartPointer<vtkTubeFilter>::New();
    tubes->SetInputData(data);
    tubes->SetRadius(radius);
    tubes->SetNumberOfSides(6);
    auto mapper = vtkSmartPointer<vtkPolyDataMapper>::New();
    mapper->SetInputConnection(tubes->GetOutputPort());
    mapper->ScalarVisibilityOff();
    auto a = vtkSmartPointer<vtkActor>::New();
    a->SetMapper(mapper);
    a->GetProperty()->SetColor(rgb[0], rgb[1], rgb[2]);
    a->GetProperty()->SetAmbient(0.5);
    renderer_->AddActor(a);
    return a;
  };
  const double tipColour[3] = {0.2, 0.75, 1.0}, ghostColour[3] = {0.8, 0.85, 0.9};
  tipTraceActor_ = traceActor(tipTrace_, tipColour, 0.006);
  ghostTraceActor_ = traceActor(ghostTrace_, ghostColour, 0.003);
  tipTraceActor_->VisibilityOff();
  ghostTraceActor_->VisibilityOff();

  // Diverging colour scale: blue (negative) - light grey (none) - red (positive).
  lut_->SetNumberOfTableValues(256);
  for (int i = 0; i < 256; ++i) {
    const double x = i / 127.5 - 1.0;
    const double mid[3] = {0.86, 0.86, 0.86}, neg[3] = {0.1, 0.3, 0.95}, pos[3] = {0.95, 0.2, 0.1};
    const double* end = x < 0 ? neg : pos;
    const double a = std::abs(x);
    lut_->SetTableValue(i, mid[0] + a * (end[0] - mid[0]), mid[1] + a * (end[1] - mid[1]),
                        mid[2] + a * (end[2] - mid[2]), 1.0);
  }
  auto light = vtkSmartPointer<vtkLight>::New();
  light->SetLightTypeToSceneLight();
  light->SetPosition(2, -2, 3);
  light->SetFocalPoint(0, 0, 0.5);
  light->SetIntensity(0.6);
  renderer_->AddLight(light);
}

void ArmScene::setSprings(int springs) {
  springs_ = std::clamp(springs, 0, 3);
  cages_[0].actor->SetVisibility(springs_ >= 1);
  cages_[1].actor->SetVisibility(springs_ >= 2);
  cages_[2].actor->SetVisibility(springs_ >= 3);
  sleeves_[0]->SetVisibility(springs_ < 1);
  sleeves_[1]->SetVisibility(springs_ < 2);
  for (auto& a : body(ArmPart::ParallelMass).actors) a->SetVisibility(springs_ >= 3);
  updateTransforms();
}

void ArmScene::setMagnification(double m) {
  if (!(m > 0) || !std::isfinite(m)) return;
  magnification_ = m;
  updateTransforms();
}

void ArmScene::setExaggeration(double e) {
  if (!(e >= 0) || !std::isfinite(e)) return;
  exaggeration_ = e;
  updateTransforms();
}

void ArmScene::setDeflectionRange(double maxDeflection) {
  maxDeflection_ = maxDeflection > 0 && std::isfinite(maxDeflection) ? maxDeflection : 1e-4;
  lut_->SetTableRange(-1e3 * maxDeflection_, 1e3 * maxDeflection_);
  lut_->Build();
  applyColours();
}

void ArmScene::setGhostVisible(bool on) {
  ghostVisible_ = on;
  for (auto& a : ghostActors_) a->SetVisibility(on);
  ghostTraceActor_->SetVisibility(on && tracePoints() > 0);
}

bool ArmScene::setPose(const BodyPose& pose) {
  if (posed_ && pose.motor == pose_.motor && pose.gearInput == pose_.gearInput &&
      pose.gearDeflection == pose_.gearDeflection && pose.armDeflection == pose_.armDeflection &&
      pose.parallelDeflection == pose_.parallelDeflection)
    return false;
  pose_ = pose;
  posed_ = true;
  updateTransforms();
  return true;
}

double ArmScene::drawnAngle(ArmPart part) const {
  const double in = magnification_ * pose_.gearInput;
  const double e = exaggeration_;
  const double gear = in - e * pose_.gearDeflection;
  switch (part) {
    case ArmPart::Motor: return pose_.motor;
    case ArmPart::GearInput: return in;
    case ArmPart::GearSpring: return in - gear;
    case ArmPart::GearOutput: return gear;
    case ArmPart::ArmSpring: return e * pose_.armDeflection;
    case ArmPart::Arm: return gear - e * pose_.armDeflection;
    case ArmPart::ParallelSpring: return e * pose_.parallelDeflection;
    case ArmPart::ParallelMass: return gear - e * pose_.parallelDeflection;
  }
  return 0.0;
}

void ArmScene::updateTransforms() {
  rotor_->Identity();
  rotor_->Translate(kMotorX, kMotorY, 0);
  rotor_->RotateZ(pose_.motor * kRadToDeg);
  rotor_->Translate(-kMotorX, -kMotorY, 0);
  const std::pair<vtkTransform*, ArmPart> turning[] = {{gearInput_, ArmPart::GearInput},
                                                       {gearOutput_, ArmPart::GearOutput},
                                                       {arm_, ArmPart::Arm},
                                                       {parallel_, ArmPart::ParallelMass}};
  for (const auto& [t, part] : turning) {
    t->Identity();
    t->RotateZ(drawnAngle(part) * kRadToDeg);
  }
  ghost_->Identity();
  ghost_->RotateZ(ghostAngle() * kRadToDeg);
  const double in = drawnAngle(ArmPart::GearInput), gear = drawnAngle(ArmPart::GearOutput);
  updateCage(cages_[0], in, gear, pose_.gearDeflection);
  updateCage(cages_[1], gear, drawnAngle(ArmPart::Arm), pose_.armDeflection);
  updateCage(cages_[2], gear, drawnAngle(ArmPart::ParallelMass), pose_.parallelDeflection);
}

void ArmScene::updateCage(Cage& c, double bottomAngle, double topAngle, double deflection) {
  c.deflection = deflection;
  for (int i = 0; i < c.bars; ++i) {
    const double base = (c.fromDeg + (c.toDeg - c.fromDeg) * i / (c.radial ? c.bars - 1 : c.bars)) / kRadToDeg;
    const double a0 = base + bottomAngle, a1 = base + topAngle;
    c.points->SetPoint(2 * i, c.r0 * std::cos(a0), c.r0 * std::sin(a0), c.z0);
    c.points->SetPoint(2 * i + 1, c.r1 * std::cos(a1), c.r1 * std::sin(a1), c.z1);
    c.scalars->SetValue(2 * i, 1e3 * deflection);
    c.scalars->SetValue(2 * i + 1, 1e3 * deflection);
  }
  c.points->Modified();
  c.scalars->Modified();
  c.lines->Modified();
}

void ArmScene::deflectionColor(double deflection, double rgb[3]) const {
  const double x = clampUnit(deflection / maxDeflection_);
  lut_->GetColor(1e3 * maxDeflection_ * x, rgb);
}

void ArmScene::setTrace(const std::vector<BodyPose>& history) {
  const std::size_t n = history.size();
  for (auto [data, ghost] : {std::pair{tipTrace_.Get(), false}, std::pair{ghostTrace_.Get(), true}}) {
    vtkPoints* pts = data->GetPoints();
    pts->SetNumberOfPoints(static_cast<vtkIdType>(n));
    for (std::size_t i = 0; i < n; ++i) {
      const BodyPose& p = history[i];
      const double in = magnification_ * p.gearInput;
      const double angle =
          ghost ? in : in - exaggeration_ * (p.gearDeflection + p.armDeflection);
      const double c = std::cos(angle), s = std::sin(angle);
      const double age = n > 1 ? static_cast<double>(n - 1 - i) / static_cast<double>(n - 1) : 0.0;
      pts->SetPoint(static_cast<vtkIdType>(i), c * tip_[0] - s * tip_[1], s * tip_[0] + c * tip_[1],
                    tip_[2] - kTraceDrop * age);
    }
    pts->Modified();
    auto cells = vtkSmartPointer<vtkCellArray>::New();
    if (n > 1) {
      std::vector<vtkIdType> ids(n);
      for (std::size_t i = 0; i < n; ++i) ids[i] = static_cast<vtkIdType>(i);
      cells->InsertNextCell(static_cast<vtkIdType>(n), ids.data());
    }
    data->SetLines(cells);
    data->Modified();
  }
  tipTraceActor_->SetVisibility(n > 1);
  ghostTraceActor_->SetVisibility(n > 1 && ghostVisible_);
}

int ArmScene::tracePoints() const {
  return static_cast<int>(tipTrace_->GetPoints()->GetNumberOfPoints());
}

void ArmScene::setHighlight(ArmPart part, bool on) {
  const auto it = std::find(highlighted_.begin(), highlighted_.end(), part);
  if (on && it == highlighted_.end()) highlighted_.push_back(part);
  if (!on && it != highlighted_.end()) highlighted_.erase(it);
  applyColours();
}

void ArmScene::clearHighlights() {
  highlighted_.clear();
  applyColours();
}

bool ArmScene::isHighlighted(ArmPart part) const {
  return std::find(highlighted_.begin(), highlighted_.end(), part) != highlighted_.end();
}

void ArmScene::applyColours() {
  for (Body& b : bodies_) {
    const bool hot = isHighlighted(b.part);
    for (std::size_t i = 0; i < b.actors.size(); ++i) {
      const double* rgb = hot ? kHighlight : b.colours[i].data();
      b.actors[i]->GetProperty()->SetColor(rgb[0], rgb[1], rgb[2]);
    }
  }
  for (Cage& c : cages_) {
    const bool hot = isHighlighted(c.part);
    // A highlighted spring is solid red with bars twice as thick; otherwise coloured by the scale.
    c.actor->GetMapper()->SetScalarVisibility(!hot);
    c.tubes->SetRadius(hot ? 2.0 * c.radius : c.radius);
    c.actor->GetProperty()->SetColor(kHighlight[0], kHighlight[1], kHighlight[2]);
  }
}

void ArmScene::resetCamera() {
  vtkCamera* cam = renderer_->GetActiveCamera();
  // Far enough to keep the tool (1.1 m from axis one) in view as the arm turns.
  cam->SetFocalPoint(0.3, 0.15, 0.55);
  cam->SetPosition(3.4, -2.9, 2.4);
  cam->SetViewUp(0, 0, 1);
  cam->SetViewAngle(30);
  renderer_->ResetCameraClippingRange();
}

}  // namespace flexarm
