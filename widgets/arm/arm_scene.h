#pragma once
// The 3D scene of the robot about axis one in VTK only: no Qt here. The masses of the chosen
// model are separate bodies, each turning about axis one by its own angle (Table 3.1): the
// motor's rotor (phi_m), the gearbox input (r phi_m), the gearbox output (phi_g), the arm
// (phi_a: base top, lower and upper arm, tool) and the parallel mass of (3.22) (phi_p). The
// springs between them are drawn as cages of bars whose twist is the deflection
// (r phi_m - phi_g, phi_g - phi_a, phi_g - phi_p) and whose colour shows it on a colour
// scale. A translucent ghost is the rigid arm (r phi_m); a trace behind the tool tip shows
// where the tip was over the last seconds (time runs downwards), beside the ghost's. Texts
// and the colour scale's legend are drawn by the widget over the picture (see ArmPanel).
//
// Drawn angles: the motion about axis one is magnified by `magnification` (the arm turns
// 1/118 of the motor angle) and the deflections, fractions of a milliradian, are exaggerated
// by a further `exaggeration`: a body at arm-side angle phi = r phi_m - delta is drawn at
// magnification * r phi_m - exaggeration * delta. Both are stated on the view.
#include <string>
#include <vector>
#include <vtkSmartPointer.h>

#include "core/sim/body_angles.h"
#include "widgets/arm/arm_parts.h"

class vtkActor;
class vtkLookupTable;
class vtkPoints;
class vtkPolyData;
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

  // Which springs exist: 0 rigid, 1 two-mass (gear spring only), 2 three-mass, 3 four-mass.
  // Springs the model lacks are drawn as solid sleeves; the parallel mass only for 3.
  void setSprings(int springs);
  int springs() const { return springs_; }
  void setMagnification(double m);
  double magnification() const { return magnification_; }
  void setExaggeration(double e);
  double exaggeration() const { return exaggeration_; }
  // The colour scale spans +-maxDeflection (rad, true size) in milliradians.
  void setDeflectionRange(double maxDeflection);
  void setGhostVisible(bool on);
  bool ghostVisible() const { return ghostVisible_; }

  // Turns the bodies to the pose (true angles, radians). Returns false (and changes nothing)
  // when the pose is the one shown, so the caller can skip a render.
  bool setPose(const BodyPose& pose);
  // Makes the next setPose count as a change (after a setting changed).
  void markChanged() { posed_ = false; }
  const BodyPose& pose() const { return pose_; }
  // The angle the part is drawn at about axis one (radians, magnified and exaggerated); the
  // motor's rotor turns by the true phi_m about its own axis. Springs: the drawn twist.
  double drawnAngle(ArmPart part) const;
  double ghostAngle() const { return magnification_ * pose_.gearInput; }
  // The colour the scale gives a deflection (rad), RGB 0..1, and the scale's end (rad).
  void deflectionColor(double deflection, double rgb[3]) const;
  double deflectionRange() const { return maxDeflection_; }

  // Past poses, oldest first, evenly spaced in time, ending at the pose shown:
  // drawn as the tool tip's trace (and the ghost tip's). Empty: no trace.
  void setTrace(const std::vector<BodyPose>& history);
  int tracePoints() const;

  // Highlights a part (e.g. the one a diagnosis names) in red until cleared.
  void setHighlight(ArmPart part, bool on);
  void clearHighlights();
  bool isHighlighted(ArmPart part) const;

  // Places the camera to see the whole arm from the front-right, slightly above.
  void resetCamera();

 private:
  struct Cage;
  struct Body;
  void build();
  void updateTransforms();
  void updateCage(Cage& cage, double bottomAngle, double topAngle, double deflection);
  void applyColours();
  Body& body(ArmPart part);

  vtkSmartPointer<vtkRenderer> renderer_;
  vtkSmartPointer<vtkLookupTable> lut_;
  vtkSmartPointer<vtkTransform> rotor_, gearInput_, gearOutput_, arm_, parallel_, ghost_;
  std::vector<Body> bodies_;
  std::vector<Cage> cages_;  // gear, arm, parallel springs
  std::vector<vtkSmartPointer<vtkActor>> sleeves_;  // solid stand-ins for missing springs
  std::vector<vtkSmartPointer<vtkActor>> ghostActors_;
  vtkSmartPointer<vtkPolyData> tipTrace_, ghostTrace_;
  vtkSmartPointer<vtkActor> tipTraceActor_, ghostTraceActor_;
  double tip_[3] = {0, 0, 0};  // tool tip at zero angle
  std::vector<ArmPart> highlighted_;
  BodyPose pose_;
  bool posed_ = false;
  int springs_ = 0;
  double magnification_ = 100.0;
  double exaggeration_ = 1000.0;
  double maxDeflection_ = 1e-4;
  bool ghostVisible_ = true;
};

}  // namespace flexarm
