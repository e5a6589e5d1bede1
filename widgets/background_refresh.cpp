#include "widgets/background_refresh.h"

#include <QtConcurrent>

namespace flexarm {

BackgroundRefresh::BackgroundRefresh(QObject* parent) : QObject(parent) {
  connect(&watcher_, &QFutureWatcher<Apply>::finished, this, &BackgroundRefresh::onFinished);
}

BackgroundRefresh::~BackgroundRefresh() {
  if (stop_) stop_->store(true);
  watcher_.waitForFinished();
}

void BackgroundRefresh::run(Work work) {
  if (running_) {
    stop_->store(true);  // its result is dropped: the newest request counts
    pending_ = std::make_unique<Work>(std::move(work));
    return;
  }
  start(std::move(work));
}

void BackgroundRefresh::cancel() {
  pending_.reset();
  if (stop_) stop_->store(true);
}

void BackgroundRefresh::start(Work work) {
  stop_ = std::make_shared<std::atomic<bool>>(false);
  running_ = true;
  watcher_.setFuture(QtConcurrent::run([work = std::move(work), stop = stop_]() -> Apply {
    try {
      Apply apply = work(*stop);
      return stop->load() ? Apply() : apply;
    } catch (...) {  // the work reports its failures through apply; this is a last guard
      return Apply();
    }
  }));
}

void BackgroundRefresh::onFinished() {
  const bool stopped = stop_ && stop_->load();
  Apply apply = watcher_.result();
  running_ = false;
  if (pending_) {
    auto next = std::move(pending_);
    start(std::move(*next));
    return;
  }
  if (stopped || !apply) return;
  apply();
  emit applied();
}

}  // namespace flexarm
