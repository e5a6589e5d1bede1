#pragma once
// The 3D scene of the robot arm (base, lower arm, upper arm, tool) in VTK only: no Qt here.
// Axis one turns the whole arm about the vertical axis; a flexible deflection bends the arm
// links (drawn as an extra rotation of the upper arm about axis one) so that the arm's
// lag behind the motor can be seen.
#include <vtkSmartPointer.h>

class vtkActor;
class vtkRenderer;
class vtkTransform;

namespace flexarm {

class ArmScene {
 public:
  ArmScene();
  ~ArmScene();
  ArmScene(const ArmScene&) = delete;
  ArmScene& operator=(const ArmScene&) = delete;

  vtkRenderer* renderer() const;

  // Axis-one angle of the motor side (after the gear) and the arm's deflection from it, rad.
  void setPose(double axisOneRad, double deflectionRad);
  double axisOne() const { return axisOne_; }
  double deflection() const { return deflection_; }

  // Places the camera to see the whole arm from the front-right, slightly above.
  void resetCamera();

 private:
  void updateTransforms();

  vtkSmartPointer<vtkRenderer> renderer_;
  vtkSmartPointer<vtkTransform> baseTurn_, lowerArm_, upperArm_, tool_;
  double axisOne_ = 0.0;
  double deflection_ = 0.0;
};

}  // namespace flexarm
