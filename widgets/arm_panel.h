#pragma once
// Arm dock: the robot in 3D (VTK, widgets/arm/arm_scene.h) turned to the window's playhead.
// Where the angles come from is chosen and named on the view: the log's motor angle through
// the gear (rigid, no model), or a physical model of the list (a fit or a hand-made model)
// simulated on the log's torque off the GUI thread (core/sim/body_angles.h), or a model
// handed in by another panel (the recursive estimator's current model). The masses then turn
// by their own angles, the springs twist and colour by their deflections at a stated,
// adjustable exaggeration, beside a ghost of the rigid arm. A diagnosis can highlight the
// part a fault lies in. The view renders only when the pose (or a setting) changed; it
// exports a still and the animation as PNG frames with an ffmpeg command line.
#include <QFutureWatcher>
#include <QWidget>
#include <atomic>
#include <memory>
#include <optional>

#include "core/sim/body_angles.h"
#include "widgets/arm/arm_overlay.h"
#include "widgets/arm/arm_parts.h"
#include "widgets/workspace.h"

class QCheckBox;
class QComboBox;
class QLabel;
class QProgressBar;
class QSpinBox;
class QToolButton;

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
  // The line under the view: where the angles come from, or what went wrong, or an export's
  // result.
  QString labelText() const;

  // The sources offered in the combo box, in order: "log" (rigid), then the list's physical
  // models, then an external model when one was handed in. Selecting one starts its
  // simulation on the log (off the GUI thread); the arm plays rigidly until it is done.
  QComboBox* sourceCombo() const { return source_; }
  // Selects the model of the list at index (-1: the log, rigid). False if it is no physical model.
  bool selectModel(int index);
  // A model from outside the list (e.g. the recursive estimator's current model), shown under
  // `name` and selected. A new call replaces it.
  // With a resultKey the model is a result of that record (Workspace::recordResult): it is
  // refused when the record does not stand and leaves the view when it is withdrawn.
  void setExternalModel(const QString& name, std::shared_ptr<const PhysicalModel> model,
                        std::vector<Effect> effects = {}, const QString& resultKey = {});
  void clearExternalModel();
  // What the arm plays now: the simulated masses (null while rigid or computing).
  std::shared_ptr<const BodyAngles> bodyAngles() const { return angles_; }
  bool isComputing() const { return watcher_.isRunning(); }
  // The sentence naming where the angles come from (also drawn on the view).
  QString sourceText() const { return sourceText_; }
  // The texts written over the view: the source and scales, and the time and deflections.
  QString captionText() const { return overlay_.caption; }
  QString statusText() const { return overlay_.status; }
  // Hides the texts and the colour legend (e.g. to compare pictures of the bodies alone).
  void setAnnotationsVisible(bool on);

  // Motion magnification about axis one and the deflections' exaggeration (see ArmScene).
  void setMagnification(int m);
  void setExaggeration(int e);
  int magnification() const;
  int exaggeration() const;
  void setGhostVisible(bool on);
  void setTraceVisible(bool on);

  // Diagnosis hook: draws part in red with the reason on the view until cleared. With a
  // resultKey the fault is a result of that record (Workspace::recordResult): it is refused
  // when the record does not stand and cleared when it is withdrawn (another log opened).
  void showFault(ArmPart part, const QString& reason, const QString& resultKey = {});
  void clearFault();
  // The highlighted part, if any.
  std::optional<ArmPart> fault() const { return fault_; }

  // The view at time t as an image (the playhead is not moved), for stills and frames.
  QImage renderAt(double t);
  // Writes frames at t0, t0 + speed/fps, ... up to t1 into folder as frame_00000.png ... and
  // ffmpeg.txt with the command that joins them into a video (run when ffmpeg is installed
  // and runFfmpeg). Renders one frame per turn of the event loop with a progress dialog and
  // Cancel; emits exportFinished.
  void exportFrames(const QString& folder, double t0, double t1, double fps, double speed,
                    bool runFfmpeg = true);
  bool isExporting() const { return exporting_; }

 public slots:
  // Diagnosis hook by name, for the Diagnosis dock to connect to: highlights the part that
  // parameter `parameter` (J_m, k_g, d_a, ... of Table 3.1, as the models name them) belongs
  // to in the model shown, with the reason on the view. The part follows the model: k_a is the
  // gear spring of the two-mass model and the arm spring of the three-mass one, so choosing
  // another source moves the highlight. A name that is no part of the arm (r, or unknown)
  // changes nothing and returns false.
  bool showParameterFault(const QString& parameter, const QString& reason, const QString& resultKey = {});

 signals:
  // A source's simulation finished (or failed: message says why); the arm plays it.
  void anglesReady(bool ok, const QString& message);
  void exportFinished(bool ok, const QString& message);

 private:
  void onLogChanged();
  void refillSources();
  void onSourceChanged();
  bool selectSource(int data);  // kLogSource, kExternalSource or a model index
  void startSimulation();
  void onSimulated();
  void updateCaption();
  BodyPose poseAt(double t) const;
  void redraw();
  void saveStill();
  void askExportFrames();

  Workspace* workspace_;
  std::unique_ptr<ArmScene> scene_;
  VtkView* view_;
  QComboBox* source_;
  QCheckBox* measured_;
  QSpinBox* magnify_;
  QSpinBox* exaggerate_;
  QCheckBox* ghost_;
  QCheckBox* trace_;
  QToolButton* export_;
  QProgressBar* progress_;
  QToolButton* cancel_;
  QLabel* label_;
  Playhead* playhead_ = nullptr;
  QFutureWatcher<BodyAngles> watcher_;
  std::shared_ptr<std::atomic<bool>> cancelFlag_;
  std::shared_ptr<const BodyAngles> angles_;
  int generation_ = 0;     // counts the choices of source
  int simGeneration_ = -1;  // the choice the running simulation is for
  struct External {
    QString name;
    QString resultKey;
    std::shared_ptr<const PhysicalModel> model;
    std::vector<Effect> effects;
  };
  std::optional<External> external_;
  // The structure of the model shown ("rigid" while the arm plays the log).
  std::string shownStructure() const;
  // Maps a fault given by parameter name onto the model shown (after the source changed).
  void placeParameterFault();

  std::optional<ArmPart> fault_;
  QString faultReason_;
  QString faultParameter_;  // set when the fault came by parameter name
  QString faultKey_;        // the result record the fault belongs to
  QString sourceText_;
  ArmOverlay overlay_;
  QString computingName_;
  double gearRatio_ = 1.0 / 118.0;
  double shownTime_ = 0.0;
  bool filling_ = false;
  bool exporting_ = false;
};

}  // namespace flexarm
