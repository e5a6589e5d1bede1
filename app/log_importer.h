#pragma once
// The window's way into logs that are not FlexArm logs: lists what the file holds off the
// GUI thread (with progress and Cancel), shows the import dialog (widgets/import_dialog.h)
// and hands the choices to MainWindow::openFile. A choice that does not open brings the
// dialog back with the reason and the choices kept.
#include <QFutureWatcher>
#include <QObject>
#include <QPointer>
#include <QString>

#include "core/io/log_source.h"
#include "widgets/import_dialog.h"

class QProgressDialog;

namespace flexarm {

class MainWindow;

class LogImporter : public QObject {
  Q_OBJECT
 public:
  explicit LogImporter(MainWindow* window);
  ~LogImporter() override;

  // Lists path in the background, then shows the dialog with `start`'s choices and, when not
  // empty, the sentence why the last choices did not open.
  void start(const QString& path, const LogReadOptions& start, const QString& problem = {});
  bool isBusy() const { return lister_.isRunning(); }
  ImportDialog* dialog() const { return dialog_; }

 signals:
  // The dialog is showing.
  void dialogShown(ImportDialog* dialog);

 private:
  void onListed();

  MainWindow* window_;
  QFutureWatcher<SourceListing> lister_;
  QProgressDialog* progress_ = nullptr;
  QPointer<ImportDialog> dialog_;
  QString path_, problem_;
  LogReadOptions start_;
  bool cancelled_ = false;
};

}  // namespace flexarm
