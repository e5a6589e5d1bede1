#pragma once
// Arm dock: the 3D arm (VTK) that the user rotates and zooms with the mouse, and a time
// slider with Play that moves axis one along the loaded log's motor angle (through the gear
// ratio, magnified so that small motions can be seen).
#include <QWidget>
#include <memory>

#include "widgets/workspace.h"

class QLabel;
class QSlider;
class QSpinBox;
class QTimer;
class QToolButton;

namespace flexarm {

class ArmScene;
class VtkView;

class ArmPanel : public QWidget {
  Q_OBJECT
 public:
  explicit ArmPanel(Workspace* workspace, QWidget* parent = nullptr);
  ~ArmPanel() override;

  VtkView* view() const { return view_; }
  ArmScene* scene() const { return scene_.get(); }
  // Shows the arm at sample index i of the current data.
  void showSample(int i);

 private:
  void onDataChanged();

  Workspace* workspace_;
  std::unique_ptr<ArmScene> scene_;
  VtkView* view_;
  QSlider* time_;
  QToolButton* play_;
  QSpinBox* magnify_;
  QLabel* label_;
  QTimer* timer_;
  double gearRatio_ = 1.0 / 118.0;
};

}  // namespace flexarm
