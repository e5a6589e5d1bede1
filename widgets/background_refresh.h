#pragma once
// Runs a panel's data-sized work off the GUI thread: the work (a function of copies and
// shared pointers, never of the panel) runs in the thread pool and returns what to do with
// its result; that runs on the GUI thread, unless a newer request superseded it meanwhile.
// Only the newest request counts, so a panel that refreshes on every change shows the
// state after the last one; a request made while one runs starts when it ends.
#include <QFutureWatcher>
#include <QObject>
#include <atomic>
#include <functional>
#include <memory>

namespace flexarm {

class BackgroundRefresh : public QObject {
  Q_OBJECT
 public:
  using Apply = std::function<void()>;
  // The work: reads its own data, polls `stop` where it can, returns the GUI-thread step.
  using Work = std::function<Apply(const std::atomic<bool>& stop)>;

  explicit BackgroundRefresh(QObject* parent = nullptr);
  ~BackgroundRefresh() override;

  // Starts work now, or as soon as the running work ends (which is then told to stop and its
  // result dropped).
  void run(Work work);
  // Drops the running and waiting work: nothing is applied.
  void cancel();
  // Work is running or waiting.
  bool isBusy() const { return running_ || pending_ != nullptr; }

 signals:
  // The newest work's result was applied.
  void applied();

 private:
  void start(Work work);
  void onFinished();

  QFutureWatcher<Apply> watcher_;
  std::shared_ptr<std::atomic<bool>> stop_;
  std::unique_ptr<Work> pending_;
  bool running_ = false;  // until the result was handled on the GUI thread
};

}  // namespace flexarm
