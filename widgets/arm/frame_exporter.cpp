#include "widgets/arm/frame_exporter.h"

#include <QDir>
#include <QFile>
#include <QImage>
#include <QProcess>
#include <QProgressDialog>
#include <QStandardPaths>
#include <QTextStream>
#include <QTimer>
#include <cmath>

#include "widgets/file_output.h"

namespace flexarm {
namespace {
constexpr std::size_t kMaxFrames = 100000;
}

std::vector<double> FrameExporter::frameTimes(double t0, double t1, double fps, double speed) {
  std::vector<double> times;
  if (!(fps > 0) || !(speed > 0) || !std::isfinite(t0) || !std::isfinite(t1) || t1 < t0) return times;
  const double step = speed / fps;
  const auto n = static_cast<std::size_t>(std::floor((t1 - t0) / step + 1e-9)) + 1;
  if (n > kMaxFrames) return times;
  times.reserve(n);
  for (std::size_t k = 0; k < n; ++k) times.push_back(t0 + static_cast<double>(k) * step);
  return times;
}

QString FrameExporter::ffmpegCommand(const QString& folder, double fps) {
  // H.264 needs even sizes: the pad filter adds a pixel where the view's size is odd.
  return QString("ffmpeg -y -framerate %1 -i \"%2/frame_%05d.png\" -vf "
                 "\"pad=ceil(iw/2)*2:ceil(ih/2)*2\" -c:v libx264 -pix_fmt yuv420p \"%2/arm.mp4\"")
      .arg(fps, 0, 'g', 6)
      .arg(QDir::toNativeSeparators(folder));
}

FrameExporter::FrameExporter(Render render, QString folder, std::vector<double> times,
                             double fps, bool runFfmpeg, QWidget* dialogParent)
    : QObject(dialogParent), render_(std::move(render)), folder_(std::move(folder)),
      times_(std::move(times)), fps_(fps), runFfmpeg_(runFfmpeg),
      progress_(new QProgressDialog(dialogParent)) {
  progress_->setWindowTitle(tr("Exporting the animation"));
  progress_->setLabelText(tr("Writing %1 frames to %2").arg(times_.size()).arg(folder_));
  progress_->setRange(0, static_cast<int>(times_.size()));
  progress_->setMinimumDuration(300);
  progress_->setAutoClose(false);
  progress_->setAutoReset(false);
  connect(progress_, &QProgressDialog::canceled, this, &FrameExporter::cancel);
}

void FrameExporter::start() {
  if (times_.empty()) {
    finish(false, tr("No frames to write: the time range is empty or needs more than %1 frames.")
                      .arg(kMaxFrames));
    return;
  }
  if (!QDir().mkpath(folder_)) {
    finish(false, tr("Cannot create the folder %1.").arg(folder_));
    return;
  }
  QTimer::singleShot(0, this, &FrameExporter::writeNext);
}

void FrameExporter::cancel() { cancelled_ = true; }

void FrameExporter::writeNext() {
  if (done_) return;
  if (cancelled_) {
    finish(false, tr("Export cancelled after %1 of %2 frames.").arg(next_).arg(times_.size()));
    return;
  }
  const QImage image = render_(times_[next_]);
  const QString path = QString("%1/frame_%2.png").arg(folder_).arg(next_, 5, 10, QChar('0'));
  QString problem;
  if (!saveImageFile(image, path, "PNG", &problem)) {
    finish(false, tr("Cannot write %1: %2").arg(path, problem));
    return;
  }
  ++next_;
  progress_->setValue(static_cast<int>(next_));
  if (next_ < times_.size()) {
    QTimer::singleShot(0, this, &FrameExporter::writeNext);
    return;
  }
  const QString command = ffmpegCommand(folder_, fps_);
  {
    QString text;
    QTextStream out(&text);
    out << "# " << times_.size() << " frames at " << fps_ << " frames a second, log time "
        << times_.front() << " - " << times_.back() << " s. Join them into arm.mp4 with:\n"
        << command << "\n";
    out.flush();
    writeFileBytes(folder_ + "/ffmpeg.txt", text.toUtf8());
  }
  QString message = tr("Wrote %1 frames to %2. Make a video with: %3")
                        .arg(times_.size())
                        .arg(folder_, command);
  if (runFfmpeg_ && !QStandardPaths::findExecutable("ffmpeg").isEmpty()) {
    auto* process = new QProcess(this);
    connect(process, &QProcess::finished, this, [this, process](int code) {
      process->deleteLater();
      finish(code == 0, code == 0 ? tr("Wrote %1/arm.mp4 (%2 frames).").arg(folder_).arg(times_.size())
                                  : tr("ffmpeg failed (exit %1); the frames are in %2.")
                                        .arg(code)
                                        .arg(folder_));
    });
    process->startCommand(command);
    return;
  }
  finish(true, message);
}

void FrameExporter::finish(bool ok, const QString& message) {
  if (done_) return;
  done_ = true;
  progress_->hide();
  progress_->deleteLater();
  emit finished(ok, message);
}

}  // namespace flexarm
