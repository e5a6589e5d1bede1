// Opens a sample log in the main window, selects ranges by dragging, preprocesses, and
// checks what the panels show, with screenshots of the window and the Arm dock.
#include <QApplication>
#include <QDir>
#include <QMessageBox>
#include <QMimeData>
#include <QPushButton>
#include <QSignalSpy>
#include <QStandardPaths>
#include <QTableWidget>
#include <QtTest>
#include <qcustomplot.h>

#include "app/main_window.h"
#include "widget_test_support.h"
#include "widgets/arm/vtk_view.h"
#include "widgets/arm_panel.h"
#include "widgets/log_panel.h"
#include "widgets/preprocess_panel.h"
#include "widgets/workspace.h"

using namespace flexarm;

namespace {
const QString kSampleLog = QString(FLEXARM_SAMPLE_DIR) + "/three_mass_estimation_chirp.csv";
}

class MainWindowTest : public QObject {
  Q_OBJECT
 private:
  MainWindow* window_ = nullptr;

  // Drags in the log plot from time t0 to t1 in the first channel's plot.
  void drag(double t0, double t1) {
    QCustomPlot* plot = window_->logPanel()->plot();
    const int y = static_cast<int>(window_->logPanel()->channelRect(0)->center().y());
    const QPoint a(static_cast<int>(std::lround(window_->logPanel()->pixelForTime(t0))), y);
    const QPoint b(static_cast<int>(std::lround(window_->logPanel()->pixelForTime(t1))), y);
    QTest::mousePress(plot, Qt::LeftButton, Qt::NoModifier, a);
    for (int i = 1; i <= 10; ++i) test::moveMouse(plot, a + (b - a) * i / 10);
    QTest::mouseRelease(plot, Qt::LeftButton, Qt::NoModifier, b);
  }

 private slots:
  void initTestCase() {
    QVERIFY2(QFile::exists(kSampleLog), qPrintable("missing sample log " + kSampleLog));
    window_ = new MainWindow;
    window_->resize(1400, 900);
    window_->show();
    QVERIFY(QTest::qWaitForWindowExposed(window_));
  }

  void opensSampleLog() {
    QSignalSpy opened(window_, &MainWindow::logOpened);
    window_->openFile(kSampleLog);
    QVERIFY(opened.wait(30000));
    const IdData* d = window_->workspace()->current();
    QVERIFY(d != nullptr);
    QCOMPARE(window_->logPanel()->channelCount(), static_cast<int>(d->channels.size()));
    QVERIFY(window_->logPanel()->channelCount() >= 3);
    QVERIFY2(window_->logPanel()->readoutText().contains("at 2000 Hz"),
             qPrintable(window_->logPanel()->readoutText()));
    QVERIFY(window_->recentFiles().contains(QFileInfo(kSampleLog).absoluteFilePath()));
    // The curves are drawn once their envelopes, formed in the background, are ready.
    QTRY_VERIFY(!window_->logPanel()->isBusy());
    QVERIFY(window_->logPanel()->plot()->graph(0)->dataCount() > 10);
  }

  void dragSelectsEstimationRange() {
    window_->logPanel()->setMode(LogPanel::Mode::SelectEstimation);
    drag(2.0, 6.0);
    auto r = window_->workspace()->range(RangeKind::Estimation);
    QVERIFY(r.has_value());
    // One pixel of the plot spans (duration / width) seconds.
    const double pixel = window_->workspace()->current()->duration() /
                         window_->logPanel()->channelRect(0)->width();
    QVERIFY2(std::abs(r->start - 2.0) <= 1.5 * pixel, qPrintable(QString::number(r->start)));
    QVERIFY2(std::abs(r->end - 6.0) <= 1.5 * pixel, qPrintable(QString::number(r->end)));
    const SampleRange s = window_->workspace()->samples(RangeKind::Estimation);
    const auto expected = static_cast<std::size_t>(std::llround((r->end - r->start) * 2000.0)) + 1;
    QCOMPARE(s.size(), expected);
    auto* table = window_->findChild<QTableWidget*>("rangeTable");
    QVERIFY(table);
    QCOMPARE(table->item(0, 3)->text(), QString::number(expected));
    QCOMPARE(table->item(1, 3)->text(), QString("drag in the plot"));
  }

  void dragSelectsValidationRange() {
    window_->logPanel()->setMode(LogPanel::Mode::SelectValidation);
    drag(14.0, 9.0);  // dragging right to left works too
    auto r = window_->workspace()->range(RangeKind::Validation);
    QVERIFY(r.has_value());
    QVERIFY(r->start < r->end);
    QVERIFY(std::abs(r->start - 9.0) < 0.1 && std::abs(r->end - 14.0) < 0.1);
    auto* table = window_->findChild<QTableWidget*>("rangeTable");
    QCOMPARE(table->item(1, 3)->text(),
             QString::number(window_->workspace()->samples(RangeKind::Validation).size()));
    window_->logPanel()->setMode(LogPanel::Mode::Navigate);
  }

  void wheelZoomsAllChannelsTogether() {
    LogPanel* panel = window_->logPanel();
    QCustomPlot* plot = panel->plot();
    const QCPRange before = panel->channelRect(0)->axis(QCPAxis::atBottom)->range();
    const QPoint at(static_cast<int>(panel->channelRect(1)->center().x()),
                    static_cast<int>(panel->channelRect(1)->center().y()));
    QWheelEvent wheel(at, plot->mapToGlobal(at), QPoint(), QPoint(0, 960), Qt::NoButton,
                      Qt::NoModifier, Qt::NoScrollPhase, false);
    QApplication::sendEvent(plot, &wheel);
    const QCPRange after = panel->channelRect(0)->axis(QCPAxis::atBottom)->range();
    QVERIFY2(after.size() < 0.5 * before.size(), qPrintable(QString::number(after.size())));
    for (int c = 1; c < panel->channelCount(); ++c)
      QCOMPARE(panel->channelRect(c)->axis(QCPAxis::atBottom)->range(), after);
    // The zoomed view is drawn from the samples in view: the first graph holds no more points
    // than about two per pixel, and they cover the visible range.
    QCPGraph* g = plot->graph(0);
    QVERIFY(g->dataCount() > 10);
    QVERIFY(g->dataCount() <= 2 * std::max(panel->channelRect(0)->width(), 800) + 16);
    QVERIFY(g->data()->constBegin()->key <= after.lower + 0.01);
    QVERIFY((g->data()->constEnd() - 1)->key >= after.upper - 0.01);
    panel->showAll();
    QCOMPARE(panel->channelRect(0)->axis(QCPAxis::atBottom)->range().size(),
             window_->workspace()->current()->duration());
  }

  void crosshairReadsValues() {
    QCustomPlot* plot = window_->logPanel()->plot();
    const int y = static_cast<int>(window_->logPanel()->channelRect(1)->center().y());
    const int x = static_cast<int>(std::lround(window_->logPanel()->pixelForTime(5.0)));
    test::moveMouse(plot, QPoint(x, y));
    const QString text = window_->logPanel()->readoutText();
    QVERIFY2(text.startsWith("t = "), qPrintable(text));
    const double t = text.mid(4, text.indexOf(" s") - 4).toDouble();
    const double pixel = window_->workspace()->current()->duration() /
                         window_->logPanel()->channelRect(0)->width();
    QVERIFY2(std::abs(t - 5.0) <= 4 * pixel, qPrintable(text));
    QVERIFY2(text.contains("torque_ref_nm = "), qPrintable(text));
  }

  void armDockRendersArm() {
    QTest::qWait(200);
    const QImage shot = window_->grab().toImage();
    test::saveShot(shot, "main_window");
    VtkView* view = window_->armPanel()->view();
    QVERIFY(view->isVisible());
    const QImage before = view->grabFramebuffer();
    test::saveShot(before, "arm_view");
    QVERIFY2(test::orangeFraction(before) > 0.005,  // the camera keeps the whole sweep of the tool in view
             qPrintable(QString("orange fraction %1").arg(test::orangeFraction(before))));
    // Dragging with the mouse rotates the camera: the picture changes.
    QTest::mousePress(view, Qt::LeftButton, Qt::NoModifier, QPoint(60, 60));
    for (int i = 1; i <= 8; ++i) QTest::mouseMove(view, QPoint(60 + 10 * i, 60));
    QTest::mouseRelease(view, Qt::LeftButton, Qt::NoModifier, QPoint(140, 60));
    const QImage after = view->grabFramebuffer();
    test::saveShot(after, "arm_view_rotated");
    QVERIFY(test::differingPixels(before, after) > before.width() * before.height() / 50);
    QVERIFY(test::orangeFraction(after) > 0.005);
  }

  void preprocessingDecimates() {
    PreprocessPanel* p = window_->preprocessPanel();
    PreprocessOptions o;
    o.differentiateAngle = true;
    o.decimation.factor = 10;
    o.detrend = Detrend::Mean;
    p->setOptions(o);
    QSignalSpy ready(p, &PreprocessPanel::previewReady);
    p->preview();
    QVERIFY(ready.wait(30000) || p->hasPreview());
    QTRY_VERIFY_WITH_TIMEOUT(p->hasPreview() && !p->isBusy(), 30000);
    p->apply();
    const IdData* d = window_->workspace()->current();
    QVERIFY(window_->workspace()->isPreprocessed());
    QCOMPARE(d->sampleRateHz(), 200.0);
    QVERIFY(d->channel(columns::kMotorVelocity) != nullptr);
    QCOMPARE(d->output()->name, std::string(columns::kMotorVelocity));
    // The ranges are kept in seconds: the estimation range now counts 200 Hz samples.
    const auto r = *window_->workspace()->range(RangeKind::Estimation);
    const SampleRange s = window_->workspace()->samples(RangeKind::Estimation);
    QVERIFY(std::abs(static_cast<double>(s.size()) - (r.end - r.start) * 200.0) <= 2.0);
    auto* table = window_->findChild<QTableWidget*>("rangeTable");
    QCOMPARE(table->item(0, 3)->text(), QString::number(s.size()));
    QTest::qWait(100);
    test::saveShot(window_->grab().toImage(), "main_window_preprocessed");
    test::saveShot(p->grab().toImage(), "preprocess_panel");
  }

  void badFileShowsErrorAndKeepsData() {
    const std::size_t before = window_->workspace()->current()->samples();
    QSignalSpy failed(window_, &MainWindow::openFailed);
    window_->openFile(QString(FLEXARM_TEST_DATA_DIR) + "/bad/non_numeric.csv");
    QVERIFY(failed.wait(10000));
    const QString msg = failed.takeFirst().at(0).toString();
    QVERIFY2(msg.contains("non_numeric.csv:") && msg.contains("column"), qPrintable(msg));
    QCOMPARE(window_->workspace()->current()->samples(), before);
  }

  void everySampleLogOpens() {
    const QStringList logs = QDir(FLEXARM_SAMPLE_DIR).entryList({"*.csv"}, QDir::Files);
    QVERIFY(logs.size() >= 12);
    for (const QString& name : logs) {
      QSignalSpy opened(window_, &MainWindow::logOpened);
      window_->openFile(QString(FLEXARM_SAMPLE_DIR) + "/" + name);
      if (name.contains("irregular_timing")) {
        // Refused as read; opened as recorded when the engineer accepts, awaiting resampling.
        QTRY_VERIFY_WITH_TIMEOUT(test::findBox("irregularTimeBox") != nullptr, 20000);
        test::findBox("irregularTimeBox")->button(QMessageBox::Open)->click();
        QVERIFY2(opened.wait(20000), qPrintable(name));
        QVERIFY(window_->workspace()->needsResampling());
        QVERIFY(window_->workspace()->raw()->input() != nullptr);
        continue;
      }
      QVERIFY2(opened.wait(20000), qPrintable(name));
      QVERIFY2(window_->logPanel()->channelCount() >= 3, qPrintable(name));
      QVERIFY(window_->workspace()->current()->input() != nullptr);
    }
    // The real DaISy table, with its column mapping given.
    LogReadOptions table;
    table.format = LogFormat::Table;
    QSignalSpy opened(window_, &MainWindow::logOpened);
    window_->openFile(QString(FLEXARM_SAMPLE_DIR) + "/daisy_robot_arm.dat", table);
    QVERIFY(opened.wait(20000));
    QCOMPARE(window_->logPanel()->channelCount(), 2);
    QCOMPARE(window_->workspace()->current()->samples(), std::size_t{1024});
  }

  void dropOpensAFile() {
    QMimeData mime;
    mime.setUrls({QUrl::fromLocalFile(QString(FLEXARM_SAMPLE_DIR) + "/effect_backlash.csv")});
    QSignalSpy opened(window_, &MainWindow::logOpened);
    QDragEnterEvent enter(QPoint(100, 100), Qt::CopyAction, &mime, Qt::LeftButton, Qt::NoModifier);
    QApplication::sendEvent(window_, &enter);
    QVERIFY(enter.isAccepted());
    QDropEvent drop(QPointF(100, 100), Qt::CopyAction, &mime, Qt::LeftButton, Qt::NoModifier);
    QApplication::sendEvent(window_, &drop);
    QVERIFY(opened.wait(20000));
    QVERIFY(opened.takeFirst().at(0).toString().endsWith("effect_backlash.csv"));
  }

  void everyShortcutIsUnique() {
    // Two actions on one key sequence make Qt ignore the key for both.
    QMap<QString, QString> seen;
    for (QAction* a : window_->findChildren<QAction*>()) {
      for (const QKeySequence& k : a->shortcuts()) {
        const QString key = k.toString();
        QVERIFY2(!seen.contains(key), qPrintable(key + ": " + seen.value(key) + " and " + a->text()));
        seen.insert(key, a->text());
      }
    }
    QVERIFY(seen.size() >= 15);
    QVERIFY(seen.contains("Ctrl+Shift+E") && seen.contains("Ctrl+Shift+R"));  // report, residuals
  }

  void cleanupTestCase() { delete window_; }
};

int main(int argc, char** argv) {
  VtkView::installDefaultSurfaceFormat();
  QApplication app(argc, argv);
  QApplication::setOrganizationName("FlexArmTests");
  MainWindowTest t;
  return QTest::qExec(&t, argc, argv);
}

#include "tst_main_window.moc"
