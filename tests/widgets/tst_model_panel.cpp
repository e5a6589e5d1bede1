// The Model panel: new model from the list, parameter edits in the table that move the notch
// and can be undone, effects switched on, and a simulation against a sample log whose truth
// is the panel's default three-mass model.
#include <QApplication>
#include <QDockWidget>
#include <cmath>
#include <QLabel>
#include <QRegularExpression>
#include <QSignalSpy>
#include <QTableWidget>
#include <QUndoStack>
#include <QtTest>
#include <qcustomplot.h>

#include "app/main_window.h"
#include "core/io/log_io.h"
#include "core/models/analysis.h"
#include "core/models/physical_models.h"
#include "widget_test_support.h"
#include "widgets/arm/vtk_view.h"
#include "widgets/bode_panel.h"
#include "widgets/model_panel.h"
#include "widgets/plots/bode_plot.h"
#include "widgets/plots/pole_zero_plot.h"
#include "widgets/workspace.h"

using namespace flexarm;

namespace {

// First notch frequency in the panel's "Notches a, b rad/s; ..." text.
double firstNotch(const QString& text) {
  const QRegularExpressionMatch m = QRegularExpression("Notches ([0-9.]+)").match(text);
  return m.hasMatch() ? m.captured(1).toDouble() : -1.0;
}

// The frequencies after `word` ("Notches 111.8, 300.2 rad/s" or "peaks ...").
QList<double> listed(const QString& text, const QString& word) {
  const auto m = QRegularExpression(word + " ([0-9., ]+) rad/s").match(text);
  QList<double> out;
  if (m.hasMatch())
    for (const QString& part : m.captured(1).split(',', Qt::SkipEmptyParts)) out << part.trimmed().toDouble();
  return out;
}

int rowOf(QTableWidget* t, const QString& name) {
  for (int r = 0; r < t->rowCount(); ++r)
    if (t->item(r, 0)->text() == name) return r;
  return -1;
}

}  // namespace

class ModelPanelTest : public QObject {
  Q_OBJECT
 private:
  MainWindow* window_ = nullptr;
  ModelPanel* panel_ = nullptr;
  QTableWidget* params_ = nullptr;

 private slots:
  void initTestCase() {
    window_ = new MainWindow;
    window_->resize(1600, 1000);
    window_->show();
    QVERIFY(QTest::qWaitForWindowExposed(window_));
    panel_ = window_->modelPanel();
    params_ = panel_->findChild<QTableWidget*>("parameterTable");
    QVERIFY(params_);
  }

  void newTwoMassModelShowsTable52Notch() {
    const int i = panel_->newModel("two-mass");
    QCOMPARE(i, 0);
    QCOMPARE(static_cast<int>(window_->workspace()->models().size()), 1);
    QVERIFY(rowOf(params_, "J_a") >= 0);
    QCOMPARE(params_->item(rowOf(params_, "J_a"), 2)->text(), QString("kg m^2"));
    // Table 5.2 puts the notch at sqrt(k/J_a) = 112 rad/s (5.4).
    QVERIFY2(std::abs(firstNotch(panel_->frequencyText()) - 111.8) < 0.5, qPrintable(panel_->frequencyText()));
    // FlexArm's one definition of notches and peaks, stated where they show and equal to what
    // `flexarm model` and the reports compute (notchesAndPeaks, core/models/analysis.h).
    const QString tip = panel_->findChild<QLabel*>("frequencyLabel")->toolTip();
    QVERIFY2(tip.contains("minima and maxima of |G(i w)|"), qPrintable(tip));
    const NotchesPeaks np = notchesAndPeaks(makeModel("two-mass")->stateSpace());
    QCOMPARE(firstNotch(panel_->frequencyText()), std::round(np.notches.at(0) * 10.0) / 10.0);
    QCOMPARE(panel_->bode()->curveCount(), 1);
    QCOMPARE(panel_->poleZero()->pointCount(), 3 + 2);  // three poles, two zeros
  }

  void editingTheTableMovesTheNotchAndUndoRestoresIt() {
    const int row = rowOf(params_, "k_a");
    QVERIFY(row >= 0);
    // Typing into the value cell, as a user would: k_a x 4 doubles the notch frequency.
    params_->item(row, 1)->setText("600000");
    QVERIFY2(std::abs(firstNotch(panel_->frequencyText()) - 2 * 111.8) < 1.0, qPrintable(panel_->frequencyText()));
    QCOMPARE(window_->workspace()->models()[0].model->value("k_a"), 6e5);
    window_->workspace()->undoStack()->undo();
    QCOMPARE(window_->workspace()->models()[0].model->value("k_a"), 1.5e5);
    QVERIFY(std::abs(firstNotch(panel_->frequencyText()) - 111.8) < 0.5);
    QCOMPARE(params_->item(row, 1)->text(), QString("150000"));
    window_->workspace()->undoStack()->redo();
    QCOMPARE(window_->workspace()->models()[0].model->value("k_a"), 6e5);
    window_->workspace()->undoStack()->undo();
  }

  void badValuesAreRefused() {
    const int row = rowOf(params_, "J_m");
    params_->item(row, 1)->setText("-3");  // below the lower bound
    QCOMPARE(window_->workspace()->models()[0].model->value("J_m"), 9e-4);
    params_->item(row, 1)->setText("abc");
    QCOMPARE(window_->workspace()->models()[0].model->value("J_m"), 9e-4);
    QVERIFY(params_->toolTip().contains("number"));
  }

  void freeFlagAndEffectsAreUndoable() {
    const int row = rowOf(params_, "f_m");
    const bool before = window_->workspace()->models()[0].model->parameters()[static_cast<std::size_t>(
        window_->workspace()->models()[0].model->indexOf("f_m"))].free;
    params_->item(row, 3)->setCheckState(before ? Qt::Unchecked : Qt::Checked);
    auto freeNow = [&] {
      const auto& m = *window_->workspace()->models()[0].model;
      return m.parameters()[static_cast<std::size_t>(m.indexOf("f_m"))].free;
    };
    QCOMPARE(freeNow(), !before);
    window_->workspace()->undoStack()->undo();
    QCOMPARE(freeNow(), before);
    auto* effects = panel_->findChild<QTableWidget*>("effectTable");
    const int backlash = rowOf(effects, "backlash");
    effects->item(backlash, 1)->setCheckState(Qt::Checked);
    QCOMPARE(window_->workspace()->models()[0].effects.size(), std::size_t{1});
    QCOMPARE(window_->workspace()->models()[0].effects[0].kind, EffectKind::Backlash);
    window_->workspace()->undoStack()->undo();
    QVERIFY(window_->workspace()->models()[0].effects.empty());
  }

  void extraMassAddsAResonance() {
    // The extra mass (250 rad/s, 0.3 of the arm) adds a pole pair and moves the notch and the
    // peak; its own resonance is less than 1 dB deep in |G(i w)|, so it adds no peak to the
    // magnitude's extrema (FlexArm's definition of notches and peaks).
    const QString before = panel_->frequencyText();
    const int pointsBefore = panel_->poleZero()->pointCount();
    QVERIFY(panel_->setEffect(EffectKind::ExtraMass, true));
    const QString after = panel_->frequencyText();
    QVERIFY2(panel_->poleZero()->pointCount() > pointsBefore, qPrintable(after));
    QVERIFY2(firstNotch(after) < firstNotch(before) - 1.0, qPrintable(before + " -> " + after));
    window_->workspace()->undoStack()->undo();
  }

  void simulatesTheTrueModelAgainstItsLog() {
    // The chirp sample log was made from the default three-mass model (its truth sidecar).
    QSignalSpy opened(window_, &MainWindow::logOpened);
    window_->openFile(QString(FLEXARM_SAMPLE_DIR) + "/three_mass_estimation_chirp.csv");
    QVERIFY(opened.wait(20000));
    panel_->newModel("three-mass");
    QSignalSpy done(panel_, &ModelPanel::simulationFinished);
    panel_->findChild<QPushButton*>("simulateButton")->click();
    QVERIFY(done.wait(30000));
    const double trueFit = done.takeFirst().at(0).toDouble();
    QVERIFY2(trueFit > 50.0, qPrintable(QString::number(trueFit)));
    QVERIFY(panel_->findChild<QLabel*>("fitLabel")->text().contains(QString::number(trueFit, 'f', 1)));
    auto* compare = panel_->findChild<QCustomPlot*>("comparePlot");
    // The 36000 samples are drawn through their envelope: two points per pixel column at most.
    const int drawn = compare->graph(0)->dataCount();
    QVERIFY2(drawn > 200 && drawn <= 2 * std::max(compare->axisRect()->width(), 800) + 8,
             qPrintable(QString::number(drawn)));
    QCOMPARE(compare->xAxis->range().upper, window_->workspace()->current()->timeAt(35999));
    window_->findChild<QDockWidget*>("modelDock")->raise();
    QTest::qWait(200);
    test::saveShot(panel_->grab().toImage(), "model_panel");
    test::saveShot(window_->grab().toImage(), "main_window_model");
    // A wrong model (arm inertia four times too large) fits the same log worse.
    QVERIFY(panel_->setParameter("J_a", 4 * 1.72));
    panel_->simulateAgainstLog();
    QVERIFY(done.wait(30000));
    const double wrongFit = done.takeFirst().at(0).toDouble();
    QVERIFY2(wrongFit < trueFit - 5.0, qPrintable(QString("%1 vs %2").arg(wrongFit).arg(trueFit)));
  }

  // Issue 20, problem 6: the Model panel's notches and peaks and the Bode panel's click readout
  // give the same numbers for the same model (both notchesAndPeaks on the exact response),
  // wherever near the extremum the user clicks.
  void bodeClickReadsTheModelPanelsNumbers() {
    const int index = panel_->newModel("three-mass");
    const QString text = panel_->frequencyText();
    const QList<double> notches = listed(text, "Notches"), peaks = listed(text, "peaks");
    QVERIFY2(notches.size() == 2 && peaks.size() == 2, qPrintable(text));
    auto* dock = window_->findChild<QDockWidget*>("bodeDock");
    dock->show();
    dock->raise();
    BodePanel* bode = window_->bodePanel();
    for (int i = 0; i < static_cast<int>(window_->workspace()->models().size()); ++i)
      bode->setModelShown(i, i == index);
    QTRY_VERIFY_WITH_TIMEOUT(!bode->isBusy() && bode->curveNames().size() == 1, 30000);
    QCustomPlot* plot = bode->plot()->plot();
    QCPAxisRect* rect = bode->plot()->magnitudeRect();
    QTest::qWait(100);
    auto readAt = [&](double w) {
      const QPoint at(qRound(rect->axis(QCPAxis::atBottom)->coordToPixel(w)), rect->center().y());
      QTest::mousePress(plot, Qt::LeftButton, Qt::NoModifier, at);
      QTest::mouseRelease(plot, Qt::LeftButton, Qt::NoModifier, at);
      const auto m = QRegularExpression("(peak|notch) at ([0-9.]+) rad/s").match(bode->plot()->readoutText());
      return m.hasMatch() ? std::make_pair(m.captured(1), m.captured(2).toDouble()) : std::make_pair(QString(), -1.0);
    };
    for (const auto& [kind, list] : {std::pair{QString("notch"), notches}, std::pair{QString("peak"), peaks}})
      for (double w : list)
        for (double off : {0.97, 1.0, 1.03}) {  // a click a little beside the extremum snaps to it
          const auto [readKind, read] = readAt(w * off);
          QVERIFY2(readKind == kind && std::abs(read - w) <= 1e-3 * w,
                   qPrintable(QString("Model panel: %1; Bode readout at %2 rad/s: %3")
                                  .arg(text).arg(w * off).arg(bode->plot()->readoutText())));
        }
  }

  void cleanupTestCase() { delete window_; }
};

int main(int argc, char** argv) {
  VtkView::installDefaultSurfaceFormat();
  QApplication app(argc, argv);
  QApplication::setOrganizationName("FlexArmTests");
  ModelPanelTest t;
  return QTest::qExec(&t, argc, argv);
}

#include "tst_model_panel.moc"
