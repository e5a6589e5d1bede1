// Dead data in the window: a log whose motor angle never moves (a stuck encoder) opens and can
// be looked at, but the Fit panel's Estimate refuses it with the sentence the command line
// prints (the one check in core/signal/excitation.h), adds no model, and the window stays
// usable; screenshots at 1366x768.
#include <QDockWidget>
#include <QPushButton>
#include <QSignalSpy>
#include <QtTest>

#include "app/main_window.h"
#include "widget_test_support.h"
#include "widgets/fit_panel.h"
#include "widgets/workspace.h"

using namespace flexarm;

class DeadDataTest : public QObject {
  Q_OBJECT

 private slots:
  void fitPanelRefusesAStuckEncoderWithTheChannelsName() {
    MainWindow window;
    window.resize(1366, 768);
    window.show();
    QVERIFY(QTest::qWaitForWindowExposed(&window));
    QSignalSpy opened(&window, &MainWindow::logOpened);
    window.openFile(QString(FLEXARM_TEST_DATA_DIR) + "/hostile/dead_stuck_encoder.csv");
    QVERIFY(opened.wait(30000));
    FitPanel* fit = window.fitPanel();
    auto* dock = window.findChild<QDockWidget*>("fitDock");
    QVERIFY(dock);
    dock->show();
    dock->raise();
    QVERIFY(fit->setModelChoice("two-mass"));
    const std::size_t before = window.workspace()->models().size();
    QSignalSpy done(fit, &FitPanel::estimated);
    QTest::mouseClick(fit->findChild<QPushButton*>("estimateButton"), Qt::LeftButton);
    QVERIFY(done.wait(60000));
    QCOMPARE(done.takeFirst().at(0).toBool(), false);
    const QString s = fit->summaryText();
    QVERIFY2(s.contains("the channel motor_angle_rad carries no signal: it is constant (every sample is 1.25)"),
             qPrintable(s));
    QCOMPARE(window.workspace()->models().size(), before);
    QTRY_VERIFY_WITH_TIMEOUT(!window.isBusy(), 30000);  // background panels settle; nothing hangs
    test::saveShot(window.grab().toImage(), "dead_data_fit_1366x768");
    test::saveShot(fit->grab().toImage(), "dead_data_fit_panel");
  }
};

QTEST_MAIN(DeadDataTest)
#include "tst_dead_data.moc"
