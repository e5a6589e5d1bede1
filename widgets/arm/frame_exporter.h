#pragma once
// Writes an animation as numbered PNG frames, one frame per turn of the event loop (the
// renderer lives on the GUI thread) so the window stays responsive, with a progress dialog
// and Cancel. Beside the frames it writes ffmpeg.txt, the command that joins them into a
// video, and runs it when ffmpeg is installed and asked for.
#include <QObject>
#include <QString>
#include <functional>
#include <vector>

class QImage;
class QProgressDialog;
class QWidget;

namespace flexarm {

class FrameExporter : public QObject {
  Q_OBJECT
 public:
  using Render = std::function<QImage(double t)>;
  // Frames at times t0, t0 + speed/fps, ... (log seconds) up to t1: a video at fps frames a
  // second shows the log at `speed` times real time.
  static std::vector<double> frameTimes(double t0, double t1, double fps, double speed);
  // The command that makes arm.mp4 from the frames in folder.
  static QString ffmpegCommand(const QString& folder, double fps);

  FrameExporter(Render render, QString folder, std::vector<double> times, double fps,
                bool runFfmpeg, QWidget* dialogParent);
  // Starts writing; finished(ok, message) comes once, after the last frame, a failure or
  // Cancel.
  void start();
  void cancel();

 signals:
  void finished(bool ok, const QString& message);

 private:
  void writeNext();
  void finish(bool ok, const QString& message);

  Render render_;
  QString folder_;
  std::vector<double> times_;
  double fps_;
  bool runFfmpeg_;
  QProgressDialog* progress_;
  std::size_t next_ = 0;
  bool cancelled_ = false;
  bool done_ = false;
};

}  // namespace flexarm
