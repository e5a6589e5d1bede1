#pragma once
// The import dialog: what a .mat file, a CSV file with other column names or a headerless
// table holds (a tree of variables, struct fields and cells with their shapes and classes, or
// the columns), a preview plot of the chosen variable, row or column, and the choices that
// make it a FlexArm log: which signal is the time, the input, the output, the arm angle and a
// closed loop's reference,
// the output's unit and side, the arm encoder's unit, the gear ratio and the input scale
// (core/io/log_mapping.h, the same description the command line and sessions use). Previews
// of a .mat file are read off the GUI thread.
#include <QDialog>
#include <QFutureWatcher>
#include <QString>

#include "core/io/log_source.h"

class QComboBox;
class QCustomPlot;
class QDoubleSpinBox;
class QLabel;
class QLineEdit;
class QPushButton;
class QSpinBox;
class QTreeWidget;
class QTreeWidgetItem;

namespace flexarm {

class ImportDialog : public QDialog {
  Q_OBJECT
 public:
  enum class Role { Time, Input, Output, Arm, Reference };

  // listing: what path holds (listLogSource); start: the choices shown first (a session's
  // or the last import's mapping).
  ImportDialog(const QString& path, SourceListing listing, const LogReadOptions& start,
               QWidget* parent = nullptr);
  ~ImportDialog() override;

  // The reading options the choices make (format, mapping, sample time).
  LogReadOptions options() const;
  // Shows a sentence above the buttons (why the last choices did not open).
  void setProblem(const QString& text);

  // What a user does, for tests and scripts: select the entry of `expression` in the tree
  // (its row or column `index` of a matrix, 1-based; 0 keeps the current one), and give the
  // selection a role.
  bool select(const QString& expression, int index = 0);
  void useSelectionAs(Role role);
  QString selectedExpression() const;
  QTreeWidget* tree() const { return tree_; }
  QCustomPlot* preview() const { return plot_; }
  QString previewTitle() const;
  int previewPoints() const;
  // The preview's horizontal axis: "time (s)" once a time (or a sample time) is chosen,
  // "sample" before.
  QString previewAxis() const;
  // Open: checks the choices (input and output given, a gear ratio for an arm side, ...) and
  // closes only when they hold; otherwise says why above the buttons.
  void accept() override;
  // A gear ratio above 1 is typed: its inverse is offered (the importGearInvert button).
  bool gearRatioInversionOffered() const;

 signals:
  // A preview was drawn (points > 0) or could not be read (points 0, the title says why).
  void previewShown(const QString& expression, int points);

 private:
  void fillTree();
  void onItemChanged();
  void updateSelection();
  void showPreview(const QString& expression);
  void onPreviewRead();
  void checkGearRatio();

  QString path_;
  SourceListing listing_;
  QTreeWidget* tree_;
  QComboBox* slice_;      // "row" or "column" of a matrix
  QSpinBox* sliceIndex_;
  QLineEdit* selected_;   // the expression of the selection, editable
  QCustomPlot* plot_;
  QLabel* previewLabel_;
  QLineEdit* roles_[5];
  QComboBox* outputUnit_;
  QComboBox* outputSide_;
  QComboBox* armUnit_;
  QLineEdit* gearRatio_;
  QPushButton* invertGear_;
  QDoubleSpinBox* inputScale_;
  QDoubleSpinBox* sampleTime_;
  QLabel* problem_;
  // A preview's signal and, when a time is chosen, the time it is drawn against.
  struct Preview {
    SeriesRead values, time;
  };
  QFutureWatcher<Preview> previewer_;
  QString previewing_, pending_;
  int points_ = 0;
};

}  // namespace flexarm
