#pragma once
// Arm dock: the 3D arm (VTK) that the user rotates and zooms with the mouse. It follows the
// window's playhead: axis one turns by the loaded log's motor angle through the gear ratio,
// magnified so that small motions can be seen.
#include <QWidget>
#include <memory>

#include "widgets/workspace.h"

class QLabel;
class QSpinBox;

namespace flexarm {

class ArmScene;
class Playhead;
class VtkView;

class ArmPanel : public QWidget {
  Q_OBJECT
 public:
  explicit ArmPanel(Workspace* workspace, QWidget* parent = nullptr);
  ~ArmPanel() override;

  VtkView* view() const { return view_; }
  ArmScene* scene() const { return scene_.get(); }
  // Follows the window's playhead.
  void setPlayhead(Playhead* playhead);
  // Shows the arm at time t (seconds of the log).
  void showTime(double t);
  QString labelText() const;

 private:
  void onDataChanged();

  Workspace* workspace_;
  std::unique_ptr<ArmScene> scene_;
  VtkView* view_;
  QSpinBox* magnify_;
  QLabel* label_;
  Playhead* playhead_ = nullptr;
  double gearRatio_ = 1.0 / 118.0;
};

}  // namespace flexarm
