#include "widgets/arm/arm_scene.h"

#include <vtkActor.h>
#include <vtkCamera.h>
#include <vtkConeSource.h>
#include <vtkCubeSource.h>
#include <vtkCylinderSource.h>
#include <vtkLight.h>
#include <vtkPlaneSource.h>
#include <vtkPolyDataMapper.h>
#include <vtkProperty.h>
#include <vtkRenderer.h>
#include <vtkSphereSource.h>
#include <vtkTransform.h>

#include <cmath>

namespace flexarm {
namespace {

constexpr double kRadToDeg = 57.29577951308232;

vtkSmartPointer<vtkActor> makeActor(vtkPolyDataAlgorithm* source, double r, double g, double b) {
  auto mapper = vtkSmartPointer<vtkPolyDataMapper>::New();
  mapper->SetInputConnection(source->GetOutputPort());
  auto actor = vtkSmartPointer<vtkActor>::New();
  actor->SetMapper(mapper);
  actor->GetProperty()->SetColor(r, g, b);
  actor->GetProperty()->SetAmbient(0.25);
  actor->GetProperty()->SetDiffuse(0.85);
  actor->GetProperty()->SetSpecular(0.3);
  actor->GetProperty()->SetSpecularPower(20);
  return actor;
}

}  // namespace

// Dimensions loosely follow an IRB 1400 (metres): base 0.475 m high, lower arm 0.6 m,
// upper arm 0.72 m, tool flange and a small tool.
ArmScene::ArmScene()
    : renderer_(vtkSmartPointer<vtkRenderer>::New()),
      baseTurn_(vtkSmartPointer<vtkTransform>::New()),
      lowerArm_(vtkSmartPointer<vtkTransform>::New()),
      upperArm_(vtkSmartPointer<vtkTransform>::New()),
      tool_(vtkSmartPointer<vtkTransform>::New()) {
  renderer_->SetBackground(0.16, 0.18, 0.22);
  renderer_->SetBackground2(0.42, 0.46, 0.52);
  renderer_->GradientBackgroundOn();

  auto floor = vtkSmartPointer<vtkPlaneSource>::New();
  floor->SetOrigin(-1.2, -1.2, 0.0);
  floor->SetPoint1(1.2, -1.2, 0.0);
  floor->SetPoint2(-1.2, 1.2, 0.0);
  floor->SetResolution(12, 12);
  auto floorActor = makeActor(floor, 0.55, 0.57, 0.6);
  floorActor->GetProperty()->SetRepresentationToWireframe();
  renderer_->AddActor(floorActor);

  // Fixed foot and the turning base (axis one is the z axis).
  auto foot = vtkSmartPointer<vtkCylinderSource>::New();
  foot->SetRadius(0.28);
  foot->SetHeight(0.12);
  foot->SetResolution(48);
  auto footActor = makeActor(foot, 0.25, 0.25, 0.28);
  auto footT = vtkSmartPointer<vtkTransform>::New();
  footT->Translate(0, 0, 0.06);
  footT->RotateX(90);  // VTK cylinders lie along y
  footActor->SetUserTransform(footT);
  renderer_->AddActor(footActor);

  auto base = vtkSmartPointer<vtkCylinderSource>::New();
  base->SetRadius(0.2);
  base->SetHeight(0.36);
  base->SetResolution(48);
  auto baseActor = makeActor(base, 0.93, 0.45, 0.1);
  auto baseLocal = vtkSmartPointer<vtkTransform>::New();
  baseLocal->SetInput(baseTurn_);
  baseLocal->Translate(0, 0, 0.3);
  baseLocal->RotateX(90);
  baseActor->SetUserTransform(baseLocal);
  renderer_->AddActor(baseActor);

  auto shoulder = vtkSmartPointer<vtkSphereSource>::New();
  shoulder->SetRadius(0.13);
  shoulder->SetThetaResolution(32);
  shoulder->SetPhiResolution(16);
  auto shoulderActor = makeActor(shoulder, 0.3, 0.3, 0.33);
  auto shoulderT = vtkSmartPointer<vtkTransform>::New();
  shoulderT->SetInput(baseTurn_);
  shoulderT->Translate(0.15, 0, 0.475);
  shoulderActor->SetUserTransform(shoulderT);
  renderer_->AddActor(shoulderActor);

  // Links are boxes placed by their joint's transform: the lower arm stands on the shoulder,
  // the upper arm reaches forwards from the elbow.
  auto addLink = [this](double lx, double ly, double lz, double cx, double cz, double r,
                        double g, double b, vtkTransform* joint) {
    auto box = vtkSmartPointer<vtkCubeSource>::New();
    box->SetXLength(lx);
    box->SetYLength(ly);
    box->SetZLength(lz);
    box->SetCenter(cx, 0, cz);
    auto actor = makeActor(box, r, g, b);
    actor->SetUserTransform(joint);
    renderer_->AddActor(actor);
  };
  addLink(0.14, 0.16, 0.6, 0, 0.3, 0.93, 0.45, 0.1, lowerArm_);
  addLink(0.72, 0.12, 0.12, 0.3, 0, 0.95, 0.55, 0.15, upperArm_);

  // Tool: a cone pointing down at the end of the upper arm.
  auto tool = vtkSmartPointer<vtkConeSource>::New();
  tool->SetHeight(0.18);
  tool->SetRadius(0.06);
  tool->SetResolution(32);
  tool->SetDirection(0, 0, -1);
  auto toolActor = makeActor(tool, 0.2, 0.6, 0.85);
  toolActor->SetUserTransform(tool_);
  renderer_->AddActor(toolActor);

  auto light = vtkSmartPointer<vtkLight>::New();
  light->SetLightTypeToSceneLight();
  light->SetPosition(2, -2, 3);
  light->SetFocalPoint(0, 0, 0.5);
  light->SetIntensity(0.6);
  renderer_->AddLight(light);

  updateTransforms();
  resetCamera();
}

ArmScene::~ArmScene() = default;

vtkRenderer* ArmScene::renderer() const { return renderer_; }

void ArmScene::setPose(double axisOneRad, double deflectionRad) {
  axisOne_ = axisOneRad;
  deflection_ = deflectionRad;
  updateTransforms();
}

void ArmScene::updateTransforms() {
  baseTurn_->Identity();
  baseTurn_->RotateZ(axisOne_ * kRadToDeg);
  // The lower arm stands on the shoulder, leaning slightly forward.
  lowerArm_->Identity();
  lowerArm_->Concatenate(baseTurn_);
  lowerArm_->Translate(0.15, 0, 0.475);
  lowerArm_->RotateY(10);
  // The flexible deflection rotates the upper arm further about the vertical through the
  // elbow, so a lag of the arm behind the motor is seen directly.
  upperArm_->Identity();
  upperArm_->Concatenate(lowerArm_);
  upperArm_->Translate(0, 0, 0.6);
  upperArm_->RotateY(-10);
  upperArm_->RotateZ(deflection_ * kRadToDeg);
  tool_->Identity();
  tool_->Concatenate(upperArm_);
  tool_->Translate(0.66, 0, -0.14);
}

void ArmScene::resetCamera() {
  vtkCamera* cam = renderer_->GetActiveCamera();
  cam->SetFocalPoint(0.25, 0, 0.6);
  cam->SetPosition(2.6, -2.4, 1.9);
  cam->SetViewUp(0, 0, 1);
  cam->SetViewAngle(30);
  renderer_->ResetCameraClippingRange();
}

}  // namespace flexarm
