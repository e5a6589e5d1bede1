// A log with irregular time stamps in the window, as an engineer meets it: opening is refused
// with the reason and an offer to open it for resampling; the Preprocess panel lists every
// jitter, gap, duplicate and reversal, a click on a row shows the place in the Log panel,
// Apply resamples (undoable) and a saved session reopens with the step. Screenshots of the
// Preprocess panel with its time-stamp report at 1366x768.
#include <QApplication>
#include <QDockWidget>
#include <QGroupBox>
#include <QMessageBox>
#include <QPushButton>
#include <QSignalSpy>
#include <QSpinBox>
#include <QTemporaryDir>
#include <QUndoStack>
#include <QtTest>
#include <cmath>
#include <qcustomplot.h>

#include "app/main_window.h"
#include "app/session_controller.h"
#include "widget_test_support.h"
#include "widgets/fit_panel.h"
#include "widgets/log_panel.h"
#include "widgets/preprocess_panel.h"
#include "widgets/timing_table.h"
#include "widgets/workspace.h"

using namespace flexarm;

namespace {

// The sample log a logger spoiled (sample_logs/README.md): data rows 3000 and 7000-7002
// dropped, row 5000 stamped 3 % late, row 9000 written twice, rows 10000 and 10001 swapped.
const QString kIrregularLog = QString(FLEXARM_SAMPLE_DIR) + "/three_mass_irregular_timing.csv";

}  // namespace

class ResampleTest : public QObject {
  Q_OBJECT
 private:
  MainWindow* window_ = nullptr;
  QTemporaryDir dir_;

 private slots:
  void initTestCase() {
    QVERIFY(dir_.isValid());
    QVERIFY(QFile::exists(kIrregularLog));
    window_ = new MainWindow;
    window_->resize(1366, 768);
    window_->show();
    QVERIFY(QTest::qWaitForWindowExposed(window_));
  }

  void openingOffersResamplingAndShowsTheLogAsRecorded() {
    window_->openFile(kIrregularLog);
    QTRY_VERIFY_WITH_TIMEOUT(test::findBox("irregularTimeBox") != nullptr, 30000);
    QMessageBox* box = test::findBox("irregularTimeBox");
    QVERIFY2(box->text().contains("2 gaps (4 samples missing, the longest 2 ms at 3.5015 s, line 7014)"),
             qPrintable(box->text()));
    QVERIFY2(box->text().contains("1 duplicate time stamp and 1 reversal"), qPrintable(box->text()));
    QVERIFY2(box->text().contains("three_mass_irregular_timing.csv:9012"), qPrintable(box->text()));
    test::saveShot(box->grab().toImage(), "resample-offer");
    QSignalSpy opened(window_, &MainWindow::logOpened);
    box->button(QMessageBox::Open)->click();
    QVERIFY(opened.wait(30000));
    Workspace* ws = window_->workspace();
    QVERIFY(ws->needsResampling());
    QVERIFY2(ws->current() == nullptr, "no analysis on irregular stamps");
    QCOMPARE(ws->raw()->samples(), std::size_t{11997});
    QCOMPARE(window_->logPanel()->channelCount(), 3);
    QVERIFY(!window_->fitPanel()->findChild<QPushButton*>("estimateButton")->isEnabled());
  }

  void panelListsTheTimeStampReportAndARowShowsItsPlace() {
    PreprocessPanel* p = window_->preprocessPanel();
    auto* group = p->findChild<QGroupBox*>("resampleGroup");
    QVERIFY2(!group->isCheckable(), "resampling is required for this log");
    QVERIFY(p->options().resample.has_value());
    QCOMPARE(p->options().resample->rateHz, 2000.0);
    p->findChild<QSpinBox*>("factorSpin")->setValue(1);  // resampling alone
    QSignalSpy ready(p, &PreprocessPanel::previewReady);
    p->preview();
    QVERIFY(ready.wait(30000));
    QVERIFY(p->hasPreview());
    TimingTable* table = p->timingTable();
    QCOMPARE(table->rowCount(), 5);
    const QString kinds[] = {"gap", "jitter", "gap", "duplicate", "reversal"};
    const int lines[] = {3015, 5014, 7014, 9012, 10013};
    const double times[] = {1.5005, 2.500015, 3.5015, 4.5, 5.0};
    for (int r = 0; r < 5; ++r) {
      QCOMPARE(table->item(r, 0)->text(), kinds[r]);
      QCOMPARE(table->item(r, 2)->text(), QString::number(lines[r]));
      QVERIFY(std::abs(table->timeOfRow(r) - times[r]) < 1e-9);
    }
    QVERIFY2(table->item(2, 3)->text().contains("3 samples missing"), qPrintable(table->item(2, 3)->text()));
    QVERIFY2(p->summaryText().contains("4 grid points filled and 1 sample retimed (bandlimited)"),
             qPrintable(p->summaryText()));

    // Clicking the long gap brings it into the middle of the Log panel.
    QSignalSpy chosen(p, &PreprocessPanel::timeSelected);
    const QRect cell = table->visualItemRect(table->item(2, 1));
    QTest::mouseClick(table->viewport(), Qt::LeftButton, Qt::NoModifier, cell.center());
    QVERIFY(chosen.count() >= 1);
    QVERIFY(std::abs(chosen.last().at(0).toDouble() - 3.5015) < 1e-9);
    const QCPRange shown = window_->logPanel()->channelRect(0)->axis(QCPAxis::atBottom)->range();
    QVERIFY2(std::abs(shown.center() - 3.5015) < 1e-6 && shown.size() < 0.1,
             qPrintable(QString("%1 .. %2").arg(shown.lower).arg(shown.upper)));
    // On a laptop screen (1366x768) the engineer closes the Arm dock to give the report and
    // the spectra the right-hand column; the panel scrolls if it is still short.
    window_->findChild<QDockWidget*>("armDock")->hide();
    QTest::qWait(200);
    window_->logPanel()->plot()->replot();
    QCOMPARE(window_->size(), QSize(1366, 768));
    test::saveShot(p->grab().toImage(), "preprocess-panel-gap-report");
    test::saveShot(window_->grab().toImage(), "resample-window-gap-report");
  }

  void applyResamplesAndUndoReturns() {
    PreprocessPanel* p = window_->preprocessPanel();
    Workspace* ws = window_->workspace();
    p->apply();
    QVERIFY(ws->current() != nullptr);
    QVERIFY(ws->current()->isUniform());
    QCOMPARE(ws->current()->samples(), std::size_t{12000});
    QVERIFY(window_->fitPanel()->findChild<QPushButton*>("estimateButton")->isEnabled());
    ws->undoStack()->undo();
    QVERIFY(ws->needsResampling());
    ws->undoStack()->redo();
    QVERIFY(!ws->needsResampling());
    QCOMPARE(ws->preprocessOptions().resample->rateHz, 2000.0);
  }

  void sessionRecordsTheStep() {
    const QString saved = dir_.filePath("resampled.json");
    QString why;
    QVERIFY2(window_->sessionController()->save(saved, &why), qPrintable(why));
    std::unique_ptr<MainWindow> other(new MainWindow);
    other->resize(1366, 768);
    other->show();
    QSignalSpy opened(other->sessionController(), &SessionController::sessionOpened);
    other->sessionController()->open(saved);
    QVERIFY(opened.wait(30000));
    QVERIFY(other->workspace()->raw()->timeStamps.size() == 11997);
    QVERIFY(other->workspace()->isPreprocessed());
    QCOMPARE(other->workspace()->current()->samples(), std::size_t{12000});
    QVERIFY(other->workspace()->current()->output()->values == window_->workspace()->current()->output()->values);
    QVERIFY(other->preprocessPanel()->options().resample.has_value());
    QCOMPARE(other->preprocessPanel()->options().resample->method, InterpolationMethod::BandLimited);
  }

  void cleanupTestCase() { delete window_; }
};

QTEST_MAIN(ResampleTest)
#include "tst_resample.moc"
