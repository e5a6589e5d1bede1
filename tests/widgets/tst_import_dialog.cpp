// The import dialog on the KUKA KR300 file, as a user drives it at 1366x768: opening the .mat
// file shows its variables (the struct rec open, the SerialLink object greyed out as skipped),
// picking a row draws it, Use selection gives it a role, Open reads axes 1-3 converted (motor
// angle = arm-side degrees x u in rad), a choice that does not hold brings the dialog back with
// the reason, and a saved session reads the file the same way again. Screenshots of the dialog
// and of the window with each axis open are saved for a person to look at.
#include <QComboBox>
#include <QDoubleSpinBox>
#include <QFile>
#include <QTextStream>
#include <QLabel>
#include <QLineEdit>
#include <QMessageBox>
#include <QPushButton>
#include <QSignalSpy>
#include <QTemporaryDir>
#include <QTreeWidget>
#include <qcustomplot.h>
#include <QtTest>
#include <algorithm>
#include <cmath>

#include "app/log_importer.h"
#include "app/main_window.h"
#include "app/session_controller.h"
#include "core/session/session.h"
#include "widget_test_support.h"
#include "widgets/import_dialog.h"
#include "widgets/workspace.h"

using namespace flexarm;

namespace {

const QString kKuka = QString(FLEXARM_SAMPLE_DIR) + "/kuka_kr300/rec_B_data.mat";
constexpr double kPi = 3.14159265358979323846;
const double kGear[3] = {256.86, 267.43, 252.33};
// The file's values at sample 1001 (read by hand, independently of FlexArm).
const double kMotDeg[3] = {-28.563801687531093, -6.402619697648896, -22.265377777092645};
const double kSeDeg[3] = {-28.631050656665067, -6.331509595658599, -22.06368389539161};

void chooseData(QComboBox* box, const QString& data) { box->setCurrentIndex(box->findData(data)); }

}  // namespace

class ImportDialogTest : public QObject {
  Q_OBJECT
 private:
  MainWindow* window_ = nullptr;
  QTemporaryDir dir_;

  // The dialog the importer shows for path after File -> Open.
  ImportDialog* openDialog(const QString& path = kKuka) {
    auto* importer = window_->findChild<LogImporter*>();
    if (!importer) return nullptr;
    QSignalSpy shown(importer, &LogImporter::dialogShown);
    window_->requestOpenFile(path);
    if (!shown.count() && !shown.wait(10000)) return nullptr;
    return importer->dialog();
  }

  // Selects expression (row `row` of a matrix) and waits for its preview.
  bool pick(ImportDialog* d, const QString& expression, int row = 0) {
    QSignalSpy shown(d, &ImportDialog::previewShown);
    if (!d->select(expression, row)) return false;
    const QString wanted = row ? QString("%1(%2,:)").arg(expression).arg(row) : expression;
    for (int i = 0; i < 20; ++i) {
      for (const auto& args : shown)
        if (args.at(0).toString() == wanted) return args.at(1).toInt() > 0;
      if (!shown.wait(2000)) break;
    }
    return false;
  }

  // Picks the axis's signals, units, side and gear ratio.
  bool chooseAxis(ImportDialog* d, int axis) {
    if (!pick(d, "rec.time_cont")) return false;
    d->useSelectionAs(ImportDialog::Role::Time);
    const std::pair<const char*, ImportDialog::Role> roles[] = {
        {"rec.act_torque_abs_nm", ImportDialog::Role::Input},
        {"rec.act_pos_mot_deg", ImportDialog::Role::Output},
        {"rec.act_pos_se_deg", ImportDialog::Role::Arm},
        {"rec.ref_pos_deg", ImportDialog::Role::Reference}};
    for (const auto& [expression, role] : roles) {
      if (!pick(d, expression, axis)) return false;
      d->useSelectionAs(role);
    }
    chooseData(d->findChild<QComboBox*>("importOutputUnit"), "deg");
    chooseData(d->findChild<QComboBox*>("importOutputSide"), "arm");
    chooseData(d->findChild<QComboBox*>("importArmUnit"), "deg");
    d->findChild<QLineEdit*>("importGearRatio")->setText(QString("1/%1").arg(kGear[axis - 1], 0, 'f', 2));
    return true;
  }

  bool clickOpen(ImportDialog* d) {
    QSignalSpy opened(window_, &MainWindow::logOpened);
    d->accept();
    return opened.wait(10000);
  }

 private slots:
  void initTestCase() {
    QVERIFY(dir_.isValid());
    window_ = new MainWindow;
    window_->sessionController()->setOfferRecovery(false);
    window_->sessionController()->setReplaceDecision([](const QString&) { return ReplaceDecision::Discard; });
    window_->resize(1366, 768);
    window_->show();
    QVERIFY(QTest::qWaitForWindowExposed(window_));
  }
  void cleanupTestCase() { delete window_; }

  void listsTheFileAndPreviewsARow() {
    ImportDialog* d = openDialog();
    QVERIFY(d);
    QVERIFY(d->isVisible());
    QTreeWidget* tree = d->tree();
    // The struct rec is listed open with its fields, shapes and classes; the object greyed.
    const auto rec = tree->findItems("rec", Qt::MatchExactly, 0);
    QCOMPARE(rec.size(), 1);
    QVERIFY(rec.front()->isExpanded());
    bool torque = false;
    for (int i = 0; i < rec.front()->childCount(); ++i) {
      const QTreeWidgetItem* f = rec.front()->child(i);
      if (f->text(0) != "act_torque_abs_nm") continue;
      torque = true;
      QCOMPARE(f->text(1), QString("6 x 2501"));
      QCOMPARE(f->text(2), QString("double"));
    }
    QVERIFY(torque);
    const auto object = tree->findItems("KR300", Qt::MatchExactly, 0);
    QCOMPARE(object.size(), 1);
    QVERIFY(object.front()->isDisabled());
    QCOMPARE(object.front()->text(2), QString("object (skipped)"));
    QVERIFY(d->findChild<QLabel*>("importNotes")->text().contains("skipped KR300 (a MATLAB object of class SerialLink)"));
    // A row of a 6 x 2501 matrix: the preview draws all of it and names it.
    QVERIFY(pick(d, "rec.act_pos_se_deg", 2));
    QCOMPARE(d->selectedExpression(), QString("rec.act_pos_se_deg(2,:)"));
    QVERIFY2(d->previewTitle().startsWith("rec.act_pos_se_deg(2,:): 2501 samples"), qPrintable(d->previewTitle()));
    QCOMPARE(d->previewPoints(), 2501);
    QCOMPARE(d->previewAxis(), QString("sample"));
    // With the time chosen, the preview is drawn against it.
    QVERIFY(pick(d, "rec.time_cont"));
    d->useSelectionAs(ImportDialog::Role::Time);
    QVERIFY(pick(d, "rec.act_pos_se_deg", 3));
    QCOMPARE(d->previewAxis(), QString("time (s)"));
    QVERIFY(std::abs(d->preview()->graph(0)->data()->at(2500)->key - 10.0) < 1e-6);
    test::saveShot(d->grab().toImage(), "import_dialog_kuka");
    d->reject();
  }

  void aChoiceThatDoesNotHoldComesBackWithTheReason() {
    ImportDialog* d = openDialog();
    QVERIFY(d);
    QVERIFY(chooseAxis(d, 1));
    // An arm side without a gear ratio is refused in the dialog itself.
    d->findChild<QLineEdit*>("importGearRatio")->clear();
    d->accept();
    QVERIFY(d->isVisible());
    QVERIFY(d->findChild<QLabel*>("importProblem")->text().contains("needs the gear ratio"));
    // A row that does not exist is refused by the reader: the dialog comes back with it.
    d->findChild<QLineEdit*>("importGearRatio")->setText("1/256.86");
    d->findChild<QLineEdit*>("importRole_output")->setText("rec.act_pos_mot_deg(7,:)");
    auto* importer = window_->findChild<LogImporter*>();
    QSignalSpy shown(importer, &LogImporter::dialogShown);
    d->accept();
    QVERIFY(shown.wait(10000));
    ImportDialog* again = importer->dialog();
    QVERIFY(again);
    QVERIFY2(again->findChild<QLabel*>("importProblem")->text().contains("row 7 is outside 1..6"),
             qPrintable(again->findChild<QLabel*>("importProblem")->text()));
    QCOMPARE(again->findChild<QLineEdit*>("importRole_input")->text(), QString("rec.act_torque_abs_nm(1,:)"));
    again->reject();
  }

  // A gear ratio typed as datasheets give it (256.86, motor turns per arm turn) would scale the
  // arm-side angle the wrong way (-0.002 rad instead of -128 rad): its inverse is offered as
  // it is typed, Open refuses it until chosen, and one click reads the axis right.
  void aGearRatioAboveOneIsOfferedInverted() {
    ImportDialog* d = openDialog();
    QVERIFY(d);
    QVERIFY(chooseAxis(d, 1));
    auto* gear = d->findChild<QLineEdit*>("importGearRatio");
    auto* invert = d->findChild<QPushButton*>("importGearInvert");
    QVERIFY(gear && invert);
    QVERIFY(!d->gearRatioInversionOffered());
    gear->setText("256.86");
    QVERIFY(d->gearRatioInversionOffered());
    QCOMPARE(invert->text(), QString("Use 1/256.86"));
    auto* problem = d->findChild<QLabel*>("importProblem");
    QVERIFY2(problem->text().contains("above 1") && problem->text().contains("1/256.86"), qPrintable(problem->text()));
    test::saveShot(d->grab().toImage(), "import_gear_ratio_inverted");
    d->accept();
    QVERIFY(d->isVisible());
    invert->click();
    QCOMPARE(gear->text(), QString("1/256.86"));
    QVERIFY(!d->gearRatioInversionOffered());
    QVERIFY(problem->text().isEmpty());
    QVERIFY(clickOpen(d));
    if (QMessageBox* box = nullptr; QTest::qWaitFor([&] { return (box = test::findBox("readWarningsBox")) != nullptr; }, 5000))
      box->close();
    const Channel* motor = window_->workspace()->raw()->channel(columns::kMotorAngle);
    QVERIFY(motor);
    QVERIFY(std::abs(motor->values[1000] - kMotDeg[0] * kGear[0] * kPi / 180.0) < 1e-9);
  }

  void opensAxesOneToThreeConverted() {
    for (int axis = 1; axis <= 3; ++axis) {
      ImportDialog* d = openDialog();
      QVERIFY(d);
      QVERIFY(chooseAxis(d, axis));
      if (axis == 1) test::saveShot(d->grab().toImage(), "import_dialog_kuka_axis1");
      QVERIFY(clickOpen(d));
      // What was skipped is shown, not only logged.
      QMessageBox* box = nullptr;
      QTRY_VERIFY((box = test::findBox("readWarningsBox")) != nullptr);
      QVERIFY2(box->text().contains("skipped KR300 (a MATLAB object of class SerialLink)"), qPrintable(box->text()));
      if (axis == 1) test::saveShot(box->grab().toImage(), "import_kuka_warnings");
      box->close();
      const IdData* data = window_->workspace()->raw();
      QVERIFY(data);
      QCOMPARE(data->samples(), std::size_t{2501});
      const Channel* motor = data->channel(columns::kMotorAngle);
      const Channel* arm = data->channel(columns::kArmAngle);
      QVERIFY(motor && arm);
      QCOMPARE(data->output(), motor);
      QVERIFY(data->isClosedLoop());  // the reference, converted as the output
      QCOMPARE(data->withRole(ChannelRole::Reference)->name, std::string(columns::kAngleRef));
      const int k = axis - 1;
      QVERIFY(std::abs(motor->values[1000] - kMotDeg[k] * kGear[k] * kPi / 180.0) < 1e-9);
      QVERIFY(std::abs(arm->values[1000] - kSeDeg[k] * kPi / 180.0) < 1e-14);
      QVERIFY(std::abs(std::stod(data->meta("gear_ratio")) - 1.0 / kGear[k]) < 1e-12);
      // The reading is part of what results computed now are computed on.
      const Provenance p = window_->workspace()->dataProvenance();
      const std::string output = "rec.act_pos_mot_deg(" + std::to_string(axis) + ",:) in deg on the arm side";
      QVERIFY(std::any_of(p.reading.begin(), p.reading.end(),
                          [&](const std::string& r) { return r.find(output) != std::string::npos; }));
      QTest::qWait(300);  // the panels draw
      test::saveShot(window_->grab().toImage(), QString("import_kuka_axis%1_window").arg(axis));
    }
  }

  // A CSV file with other column names and a headerless table go through the same dialog:
  // header names (or column numbers) offered, previews, names and units set there.
  void otherColumnNamesAndTablesThroughTheDialog() {
    const QString csv = dir_.filePath("bench.csv");
    {
      QFile f(csv);
      QVERIFY(f.open(QIODevice::WriteOnly | QIODevice::Text));
      QTextStream out(&f);
      out << "t_s,torque_motor_Nm,pos_motor_deg_linkside,pos_link_deg\n";
      for (int i = 0; i < 50; ++i) out << 0.002 * i << "," << 0.5 * i << "," << 0.1 * i << "," << 0.1 * i - 0.002 << "\n";
    }
    ImportDialog* d = openDialog(csv);
    QVERIFY(d);
    QCOMPARE(d->tree()->topLevelItemCount(), 4);
    QCOMPARE(d->tree()->topLevelItem(2)->text(0), QString("pos_motor_deg_linkside"));
    const std::pair<const char*, ImportDialog::Role> roles[] = {{"t_s", ImportDialog::Role::Time},
                                                                {"torque_motor_Nm", ImportDialog::Role::Input},
                                                                {"pos_motor_deg_linkside", ImportDialog::Role::Output},
                                                                {"pos_link_deg", ImportDialog::Role::Arm}};
    for (const auto& [name, role] : roles) {
      QVERIFY(pick(d, name));
      d->useSelectionAs(role);
    }
    QCOMPARE(d->previewPoints(), 50);
    chooseData(d->findChild<QComboBox*>("importOutputUnit"), "deg");
    chooseData(d->findChild<QComboBox*>("importOutputSide"), "arm");
    chooseData(d->findChild<QComboBox*>("importArmUnit"), "deg");
    d->findChild<QLineEdit*>("importGearRatio")->setText("1/100");
    QVERIFY(clickOpen(d));
    const IdData* data = window_->workspace()->raw();
    QVERIFY(std::abs(data->sampleTime - 0.002) < 1e-12);
    QCOMPARE(data->output()->name, std::string(columns::kMotorAngle));
    QVERIFY(std::abs(data->output()->values[10] - 1.0 * 100 * kPi / 180) < 1e-12);
    QVERIFY(std::abs(data->channel(columns::kArmAngle)->values[10] - (1.0 - 0.002) * kPi / 180) < 1e-15);
    QVERIFY(!test::findBox("readWarningsBox"));  // everything was said

    // The DaISy table: columns by number, the sample time given, the output read as stored.
    d = openDialog(QString(FLEXARM_SAMPLE_DIR) + "/daisy_robot_arm.dat");
    QVERIFY(d);
    QCOMPARE(d->tree()->topLevelItem(0)->text(0), QString("column 1"));
    QVERIFY(pick(d, "column 1"));
    d->useSelectionAs(ImportDialog::Role::Input);
    QVERIFY(pick(d, "column 2"));
    d->useSelectionAs(ImportDialog::Role::Output);
    QVERIFY2(d->previewTitle().startsWith("column 2: 1024 samples"), qPrintable(d->previewTitle()));
    d->findChild<QDoubleSpinBox*>("importSampleTime")->setValue(0.1);
    QVERIFY(clickOpen(d));
    QCOMPARE(window_->workspace()->raw()->samples(), std::size_t{1024});
    QVERIFY(std::abs(window_->workspace()->raw()->sampleTime - 0.1) < 1e-12);
    QMessageBox* box = nullptr;
    QTRY_VERIFY((box = test::findBox("readWarningsBox")) != nullptr);
    QVERIFY2(box->text().contains("the output column 2 is read as stored"), qPrintable(box->text()));
    box->close();
  }

  void aSessionReadsTheFileTheSameWay() {
    ImportDialog* d = openDialog();
    QVERIFY(d);
    QVERIFY(chooseAxis(d, 3));
    QVERIFY(clickOpen(d));
    if (QMessageBox* box = test::findBox("readWarningsBox")) box->close();
    const LogReadOptions read = window_->workspace()->logReadOptions();
    QCOMPARE(read.mapping.output, std::string("rec.act_pos_mot_deg(3,:)"));
    const QString path = dir_.filePath("kuka.json");
    QString why;
    QVERIFY2(window_->sessionController()->save(path, &why), qPrintable(why));
    const SessionParseResult parsed = loadSession(path.toStdString());
    QVERIFY(parsed.ok);
    QVERIFY(parsed.session.logs.front().read.mapping == read.mapping);
    // Another log replaces it, then the session brings back axis 3, read as before.
    QSignalSpy opened(window_, &MainWindow::logOpened);
    window_->openFile(QString(FLEXARM_SAMPLE_DIR) + "/three_mass_estimation_chirp.csv", LogReadOptions{});
    QVERIFY(opened.wait(10000));
    QVERIFY(!window_->workspace()->raw()->channel(columns::kArmAngle));
    QSignalSpy restored(window_->sessionController(), &SessionController::sessionOpened);
    window_->sessionController()->open(path);
    QVERIFY(restored.wait(10000));
    const Channel* motor = window_->workspace()->raw()->channel(columns::kMotorAngle);
    QVERIFY(motor);
    QVERIFY(std::abs(motor->values[1000] - kMotDeg[2] * kGear[2] * kPi / 180.0) < 1e-9);
    QVERIFY(window_->workspace()->logReadOptions().mapping == read.mapping);
  }
};

QTEST_MAIN(ImportDialogTest)
#include "tst_import_dialog.moc"
