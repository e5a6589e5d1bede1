// Results tied to their data, and work that is never thrown away unasked: a fit made on the
// chirp log keeps its log, checksum and numbers when effect_backlash.csv is opened (the report
// shows them and says which log is open, and recomputes nothing on it); estimates on different
// data get different names; the window offers to recompute them; the session keeps the
// provenance; opening a log over unsaved work asks Save / Discard / Cancel, and Cancel keeps
// ranges, preprocessing and the undo history.
#include <QAbstractButton>
#include <QApplication>
#include <QComboBox>
#include <QFile>
#include <QListWidget>
#include <QMessageBox>
#include <QPushButton>
#include <QRegularExpression>
#include <QSignalSpy>
#include <QTemporaryDir>
#include <QTimer>
#include <QUndoStack>
#include <QtTest>

#include "app/main_window.h"
#include "app/session_controller.h"
#include "core/session/fit_request.h"
#include "core/session/session.h"
#include "core/session/report.h"
#include "core/session/sha256.h"
#include "core/signal/preprocess.h"
#include "widget_test_support.h"
#include "widgets/fit_panel.h"
#include "widgets/workspace.h"

using namespace flexarm;

namespace {

const QString kChirp = QString(FLEXARM_SAMPLE_DIR) + "/three_mass_estimation_chirp.csv";
const QString kBacklash = QString(FLEXARM_SAMPLE_DIR) + "/effect_backlash.csv";

std::string sumOf(const QString& path) { return sha256OfFile(path.toStdString(), nullptr).value_or("?"); }

bool clickEstimate(FitPanel* fit) {
  QSignalSpy done(fit, &FitPanel::estimated);
  QTest::mouseClick(fit->findChild<QPushButton*>("estimateButton"), Qt::LeftButton);
  if (!done.wait(120000)) return false;
  return done.takeFirst().at(0).toBool();
}

QString pdfText(const QString& pdf) {
  if (std::system(qPrintable("pdftotext -layout '" + pdf + "' '" + pdf + ".txt'")) != 0) return {};
  QFile t(pdf + ".txt");
  if (!t.open(QIODevice::ReadOnly)) return {};
  // NFKC turns the PDF's ligatures ("ﬀ", "ﬁ") back into letters.
  return QString::fromUtf8(t.readAll()).normalized(QString::NormalizationForm_KC).simplified();
}

// Whether text holds words, wherever the PDF's lines broke them (spaces are ignored).
bool holds(QString text, QString words) {
  return text.remove(QRegularExpression("\\s")).contains(words.remove(QRegularExpression("\\s")));
}

}  // namespace

class WorkspaceProvenanceTest : public QObject {
  Q_OBJECT
 private:
  MainWindow* window_ = nullptr;
  QTemporaryDir dir_;
  QStringList asked_;  // what each Save / Discard / Cancel question was about
  ReplaceDecision answer_ = ReplaceDecision::Cancel;
  QString chirpFit_;   // the estimate made on the chirp log
  FitRequest chirpRequest_;

  bool openAsUser(const QString& path) {
    QSignalSpy opened(window_, &MainWindow::logOpened);
    window_->requestOpenFile(path);
    return opened.wait(3000);
  }

 private slots:
  void initTestCase() {
    QVERIFY(dir_.isValid());
    window_ = new MainWindow;
    window_->resize(1366, 768);
    window_->show();
    QVERIFY(QTest::qWaitForWindowExposed(window_));
    QFile::remove(window_->sessionController()->autosavePath());
    window_->sessionController()->setReplaceDecision([this](const QString& what) {
      asked_ << what;
      return answer_;
    });
    QSignalSpy opened(window_, &MainWindow::logOpened);
    window_->openFile(kChirp);
    QVERIFY(opened.wait(30000));
    QVERIFY(!window_->sessionController()->isDirty());
    QVERIFY(!window_->isWindowModified());
  }

  // (d) and the fit's record: the estimate names its data and keeps log, checksum, steps.
  void fitRecordsItsDataAndANameOfItsOwn() {
    Workspace* ws = window_->workspace();
    PreprocessOptions p;
    p.differentiateAngle = true;
    p.decimation.factor = 10;
    p.detrend = Detrend::Mean;
    ws->setPreprocessed(preprocess(*ws->raw(), p), p);
    ws->setRange(RangeKind::Estimation, {0.5, 12.0});
    ws->setRange(RangeKind::Validation, {12.0, 17.5});
    QVERIFY(window_->sessionController()->isDirty());
    QVERIFY(window_->isWindowModified());
    FitPanel* fit = window_->fitPanel();
    QVERIFY(fit->setModelChoice("three-mass"));
    fit->setFreeParameters({"k_g", "k_a"});
    fit->setDecimation(1);
    QVERIFY2(clickEstimate(fit), qPrintable(fit->summaryText()));
    const ModelEntry e = ws->models().back();
    chirpFit_ = nameOf(e);
    QCOMPARE(nameOf(e), QString("three-mass estimate (three_mass_estimation_chirp.csv 0.5-12 s)"));
    QVERIFY(e.fitRequest && e.fitRequest->provenance && e.fitRequest->stored);
    chirpRequest_ = *e.fitRequest;
    const Provenance& pr = *e.fitRequest->provenance;
    QCOMPARE(pr.sha256, sumOf(kChirp));
    QCOMPARE(pr.log, std::string("three_mass_estimation_chirp.csv"));
    QCOMPARE(pr.preprocessing, describePreprocessing(p));
    QVERIFY(pr.validation && pr.validation->end == 17.5);
    // A second fit of the same structure on the same data is still told apart.
    QVERIFY2(clickEstimate(fit), qPrintable(fit->summaryText()));
    QCOMPARE(nameOf(ws->models().back()), QString("three-mass estimate 2 (three_mass_estimation_chirp.csv 0.5-12 s)"));
    ws->undoStack()->undo();  // the second estimate goes again
    QCOMPARE(nameOf(ws->models().back()), chirpFit_);
  }

  // (b) Opening a log over unsaved work asks first; Cancel keeps everything.
  void cancelKeepsRangesPreprocessingAndUndo() {
    Workspace* ws = window_->workspace();
    const int undoSteps = ws->undoStack()->count();
    const std::size_t models = ws->models().size();
    QVERIFY(undoSteps >= 4);
    asked_.clear();
    answer_ = ReplaceDecision::Cancel;
    QVERIFY(!openAsUser(kBacklash));
    QCOMPARE(asked_, QStringList{"opening effect_backlash.csv"});
    QCOMPARE(ws->logPath(), kChirp);
    QVERIFY(ws->isPreprocessed());
    QCOMPARE(ws->range(RangeKind::Estimation)->end, 12.0);
    QCOMPARE(ws->undoStack()->count(), undoSteps);
    QCOMPARE(ws->models().size(), models);
    QVERIFY(window_->isWindowModified());
    // Closing the window asks too, and Cancel keeps it open.
    window_->close();
    QVERIFY(window_->isVisible());
    QCOMPARE(asked_.size(), 2);
    QCOMPARE(asked_.back(), QString("closing the window"));
  }

  // The real question, as a user sees it: a message box with Save, Discard and Cancel.
  void theQuestionIsAMessageBox() {
    window_->sessionController()->setReplaceDecision(nullptr);
    QString text;
    bool hadButtons = false;
    QTimer::singleShot(300, this, [&] {
      QMessageBox* box = test::findBox("replaceBox");
      if (!box) return;
      text = box->text();
      hadButtons = box->button(QMessageBox::Save) && box->button(QMessageBox::Discard) &&
                   box->button(QMessageBox::Cancel);
      test::saveShot(window_->grab().toImage(), "provenance-window-dirty");
      test::saveShot(box->grab().toImage(), "provenance-replace-prompt");
      box->button(QMessageBox::Cancel)->click();
    });
    QVERIFY(!window_->sessionController()->confirmReplace("opening effect_backlash.csv"));
    QVERIFY2(text.contains("opening effect_backlash.csv"), qPrintable(text));
    QVERIFY(hadButtons);
    QVERIFY(window_->workspace()->isPreprocessed());
    window_->sessionController()->setReplaceDecision([this](const QString& what) {
      asked_ << what;
      return answer_;
    });
  }

  // (c) The session keeps the provenance and the stored numbers of the fit.
  void sessionRoundTripKeepsProvenance() {
    const QString path = dir_.filePath("chirp.json");
    QString why;
    QVERIFY2(window_->sessionController()->save(path, &why), qPrintable(why));
    QVERIFY(!window_->isWindowModified());
    const auto loaded = loadSession(path.toStdString());
    QVERIFY2(loaded.ok, loaded.message.c_str());
    const auto& request = loaded.session.parts["fits"]["requests"][0];
    QCOMPARE(QString::fromStdString(request["provenance"]["sha256"]), QString::fromStdString(sumOf(kChirp)));
    QCOMPARE(QString::fromStdString(loaded.session.parts["models"].back()["provenance"]["log"]),
             QString("three_mass_estimation_chirp.csv"));
    std::unique_ptr<MainWindow> other(new MainWindow);
    QSignalSpy opened(other->sessionController(), &SessionController::sessionOpened);
    other->sessionController()->open(path);
    QVERIFY(opened.wait(30000));
    const ModelEntry& e = other->workspace()->models().back();
    QCOMPARE(nameOf(e), chirpFit_);
    QVERIFY(e.fitRequest && e.fitRequest->provenance && e.fitRequest->stored);
    QVERIFY(*e.fitRequest->provenance == *chirpRequest_.provenance);
    QCOMPARE(e.fitRequest->stored->parameters.size(), chirpRequest_.stored->parameters.size());
    for (std::size_t i = 0; i < e.fitRequest->stored->parameters.size(); ++i)
      QCOMPARE(e.fitRequest->stored->parameters[i].value, chirpRequest_.stored->parameters[i].value);
    QVERIFY(other->sessionController()->staleEstimates().isEmpty());
    window_->workspace()->setRange(RangeKind::Validation, {12.0, 17.0});  // unsaved work again
  }

  // (a) Fit on the chirp log, open effect_backlash.csv (Discard), export the report.
  void reportOnAnotherLogShowsTheFitsOwnData() {
    answer_ = ReplaceDecision::Discard;
    asked_.clear();
    QSignalSpy offered(window_->sessionController(), &SessionController::recomputeOffered);
    QVERIFY(openAsUser(kBacklash));
    QCOMPARE(asked_.size(), 1);
    Workspace* ws = window_->workspace();
    QCOMPARE(ws->logPath(), kBacklash);
    QVERIFY(!ws->isPreprocessed());
    QCOMPARE(ws->undoStack()->count(), 0);
    QVERIFY(!window_->isWindowModified());
    // The estimate stays, tied to its data, and the window offers to recompute it.
    QVERIFY(offered.count() == 1 || offered.wait(2000));
    QMessageBox* box = test::findBox("recomputeBox");
    QVERIFY(box != nullptr);
    QVERIFY2(box->text().contains("the open log is effect_backlash.csv"), qPrintable(box->text()));
    test::saveShot(box->grab().toImage(), "provenance-recompute-offer");
    const auto stale = window_->sessionController()->staleEstimates();
    QCOMPARE(stale.size(), 1);
    QCOMPARE(stale.front().first, chirpFit_);
    box->close();

    const QString pdf = dir_.filePath("report.pdf");
    QSignalSpy done(window_->sessionController(), &SessionController::reportExported);
    window_->sessionController()->exportReport(pdf);
    QVERIFY(done.wait(60000));
    const QString text = pdfText(pdf);
    QVERIFY(!text.isEmpty());
    QDir().mkpath(FLEXARM_SCREENSHOT_DIR);
    QCOMPARE(std::system(qPrintable("pdftoppm -png -r 70 '" + pdf + "' '" + QString(FLEXARM_SCREENSHOT_DIR) +
                                    "/provenance-report-page'")),
             0);
    QVERIFY2(holds(text, "Fit " + chirpFit_), qPrintable(text));
    QVERIFY2(holds(text, "computed on three_mass_estimation_chirp.csv (SHA-256 " +
                             QString::fromStdString(sumOf(kChirp).substr(0, 16))),
             qPrintable(text));
    QVERIFY2(holds(text, "the open log is effect_backlash.csv"), qPrintable(text));
    // The stored numbers: k_g as the Fit panel estimated it on the chirp log.
    double kg = 0.0;
    for (const auto& p : chirpRequest_.stored->parameters)
      if (p.name == "k_g") kg = p.value;
    QVERIFY(kg > 0.0);
    QVERIFY2(holds(text, QString::fromStdString(formatSignificant(kg, 6))), qPrintable(text));

    // The same fit recomputed on the backlash log (through the window's offer) gives other
    // numbers under another name; none of them is in the report.
    QSignalSpy estimated(window_->fitPanel(), &FitPanel::estimated);
    window_->sessionController()->recomputeStale();
    QVERIFY(estimated.wait(120000));
    QVERIFY2(estimated.first().first().toBool(), qPrintable(window_->fitPanel()->summaryText()));
    const ModelEntry& again = ws->models().back();
    QVERIFY2(nameOf(again).startsWith("three-mass estimate 2 (effect_backlash.csv"), qPrintable(nameOf(again)));
    QVERIFY(nameOf(again) != chirpFit_);
    double kgB = 0.0;
    for (const auto& p : again.fitRequest->stored->parameters)
      if (p.name == "k_g") kgB = p.value;
    const QString b = QString::fromStdString(formatSignificant(kgB, 6));
    QVERIFY(b != QString::fromStdString(formatSignificant(kg, 6)));
    QVERIFY2(!text.contains(b), qPrintable(b + " (recomputed on the backlash log) is in the report"));
    QVERIFY(window_->sessionController()->staleEstimates().size() == 1);  // the chirp one stays
    // Compare and Bode tick the models of the open log; the chirp's estimate is listed, greyed
    // with its data in the tooltip, unticked. Residuals opens on the backlash log's estimate.
    for (const char* name : {"compareModelList", "bodeModelList"}) {
      auto* list = window_->findChild<QListWidget*>(name);
      QVERIFY2(list, name);
      QCOMPARE(list->count(), static_cast<int>(ws->models().size()));
      for (int i = 0; i < list->count(); ++i) {
        const QString item = list->item(i)->text();
        if (item.contains("three_mass_estimation_chirp.csv")) {
          QVERIFY2(list->item(i)->checkState() == Qt::Unchecked, qPrintable(QString(name) + ": " + item));
          QVERIFY(list->item(i)->toolTip().startsWith("Of other data than the open log"));
        } else if (item.contains("effect_backlash.csv")) {
          QVERIFY2(list->item(i)->checkState() == Qt::Checked, qPrintable(QString(name) + ": " + item));
        }
      }
    }
    auto* residualsModel = window_->findChild<QComboBox*>("residualsModelCombo");
    QVERIFY(residualsModel);
    QCOMPARE(residualsModel->currentText(), nameOf(again));
  }

  void cleanupTestCase() {
    window_->sessionController()->setReplaceDecision([](const QString&) { return ReplaceDecision::Discard; });
    delete window_;
  }
};

QTEST_MAIN(WorkspaceProvenanceTest)
#include "tst_workspace_provenance.moc"
