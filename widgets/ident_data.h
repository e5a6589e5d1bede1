#pragma once
// What the identification panels (Fit, Bode, Compare, Residuals) share: the workspace's data
// as input and output vectors with their estimation and validation ranges, and the models of
// the shared list (physical or black-box) simulated, predicted and as frequency responses.
#include <QString>
#include <optional>
#include <vector>

#include <Eigen/Dense>

#include "core/compare/compare.h"
#include "core/ident/evaluation.h"
#include "core/ident/fit.h"
#include "widgets/workspace.h"

class QListWidget;

namespace flexarm {

// A copy of a physical model that can be edited (the list shares const models).
std::shared_ptr<PhysicalModel> clonePhysical(const ParametricModel& model);

// Whether the entry belongs with the open data: made by hand, or estimated on the log that is
// open (read and preprocessed alike; core's sameData).
bool ofOpenData(const ModelEntry& entry, const Workspace& workspace);

// Fills a list widget with the shared list's model names as check boxes. A model of the open
// data is checked unless the user unchecked it; a model of other data is unchecked unless the
// user checked it while it was, and its item says so (greyed, its data in the tooltip). So a
// newly opened log shows its own models, not every estimate the list ever held.
void fillModelChecklist(QListWidget* list, const std::vector<ModelEntry>& models, const Workspace& workspace);
bool isModelChecked(const QListWidget* list, std::size_t index);

// What the identification panels read from the workspace, taken on the GUI thread so that
// work in the background sees it unchanged: the current data (shared) and the ranges.
struct WorkspaceSnapshot {
  std::shared_ptr<const IdData> data;
  std::optional<TimeRange> estimation, validation;
  std::string name;  // the log's file name
};
WorkspaceSnapshot snapshotOf(const Workspace& workspace);
// The snapshot as core's evaluations (runCompare, runResiduals) take their data.
EvaluationData evaluationDataOf(const WorkspaceSnapshot& snapshot);

// The workspace's current data prepared as the fit pipeline prepares them (prepareFitData,
// core/ident/fit_data.h): the workspace's estimation and validation ranges, decimation behind
// the anti-alias FIR when decimation > 1, the motor velocity from the motor angle when
// velocityOutput (the physical models' output), the estimation data's means removed (Section
// 5.2). nullopt with a sentence in why when there are no usable data.
std::optional<PreparedData> workspaceData(const Workspace& workspace, int decimation, bool velocityOutput,
                                          QString* why);
// The same from a snapshot, on any thread.
std::optional<PreparedData> workspaceData(const WorkspaceSnapshot& snapshot, int decimation,
                                          bool velocityOutput, QString* why);

// The quantity and unit the models' output is drawn in: the output channel's name and unit,
// or its derivative ("d/dt motor_angle_rad [rad/s]") when the models give the velocity.
QString outputAxisLabel(const Workspace& workspace, bool velocityOutput);

// The workspace's current data and ranges as the experiments of a fit: the estimation range
// (the whole log without one) and, when one is set, the validation range of the same log.
void useWorkspaceData(const Workspace& workspace, FitOptions& options);

// Frequency response at omega (rad/s) with bands at `level` where the entry has a covariance
// (estimateResponse of the fit pipeline). Black-box responses stop at their Nyquist frequency.
FrequencyResponse responseOf(const ModelEntry& entry, const std::vector<double>& omega,
                             double level);

// The linear model a physical entry's analysis looks at: motor velocity output with its
// structural effects (an extra mass) applied. nullopt for a black-box entry. The Model panel
// prints its notchesAndPeaks and the Bode panel's click reads the same values.
std::optional<StateSpace> analysedStateSpace(const ModelEntry& entry);

}  // namespace flexarm
