#include "app/log_importer.h"

#include <QFileInfo>
#include <QMessageBox>
#include <QProgressDialog>
#include <QStatusBar>
#include <QtConcurrent>

#include "app/busy_progress.h"
#include "app/main_window.h"
#include "widgets/import_dialog.h"

namespace flexarm {

LogImporter::LogImporter(MainWindow* window) : QObject(window), window_(window) {
  connect(&lister_, &QFutureWatcher<SourceListing>::finished, this, &LogImporter::onListed);
}

LogImporter::~LogImporter() { lister_.waitForFinished(); }

void LogImporter::start(const QString& path, const LogReadOptions& start, const QString& problem) {
  if (lister_.isRunning()) return;
  if (dialog_) dialog_->close();
  path_ = path;
  start_ = start;
  problem_ = problem;
  startBusyProgress(progress_, window_, tr("Import"), tr("Reading what %1 holds").arg(QFileInfo(path).fileName()),
                    &cancelled_);
  window_->statusBar()->showMessage(tr("Reading what %1 holds...").arg(path));
  const std::string p = path.toStdString();
  LogReadOptions limits;
  limits.maxFileBytes = start.maxFileBytes;
  lister_.setFuture(QtConcurrent::run([p, limits] { return listLogSource(p, limits); }));
}

void LogImporter::onListed() {
  if (progress_) progress_->hide();
  if (cancelled_) {
    window_->statusBar()->showMessage(tr("Opening %1 cancelled").arg(path_), 5000);
    return;
  }
  SourceListing listing = lister_.result();
  if (!listing.ok) {
    const QString message = QString::fromStdString(listing.error.toString());
    window_->statusBar()->showMessage(tr("Could not open %1").arg(path_), 10000);
    auto* box = new QMessageBox(QMessageBox::Warning, tr("Could not open the log"), message, QMessageBox::Ok, window_);
    box->setObjectName("errorBox");
    box->setAttribute(Qt::WA_DeleteOnClose);
    box->open();
    emit window_->openFailed(message);
    return;
  }
  window_->statusBar()->clearMessage();
  dialog_ = new ImportDialog(path_, std::move(listing), start_, window_);
  dialog_->setAttribute(Qt::WA_DeleteOnClose);
  dialog_->setProblem(problem_);
  const QString path = path_;
  connect(dialog_, &QDialog::accepted, this, [this, path] {
    const LogReadOptions options = dialog_->options();
    window_->openFile(path, options);
  });
  connect(dialog_, &QDialog::rejected, this,
          [this, path] { window_->statusBar()->showMessage(tr("Opening %1 cancelled").arg(path), 5000); });
  dialog_->open();
  emit dialogShown(dialog_);
}

}  // namespace flexarm
