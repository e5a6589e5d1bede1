#include "app/session_parts.h"

#include <QByteArray>
#include <QStringList>
#include <QVariant>

#include "app/main_window.h"
#include "app/panel_docks.h"
#include "core/diagnosis/diagnosis_json.h"
#include "core/session/diagnosis_part.h"
#include "core/session/discovery_part.h"
#include "core/session/fit_request.h"
#include "core/session/lqg_part.h"
#include "core/session/model_json.h"
#include "app/session_controller.h"
#include "widgets/diagnosis_panel.h"
#include "core/session/recursive_part.h"
#include "widgets/discovery_panel.h"
#include "widgets/fit_panel.h"
#include "widgets/lqg_panel.h"
#include "widgets/model_panel.h"
#include "widgets/recursive_panel.h"
#include "widgets/workspace.h"

namespace flexarm {
namespace {

using nlohmann::json;

// The data of the result the part's panel shows, as the workspace records it
// (Workspace::recordResult): a section is saved with them.
json withProvenance(json section, const MainWindow& w, const char* key) {
  const auto p = w.workspace()->resultData(key);
  if (p && section.is_object() && !section.contains("provenance")) section["provenance"] = provenanceToJson(*p);
  return section;
}

// A restored section's data become the panel's result record, so that saving again keeps
// them and opening another log withdraws the result; a section without them (written
// before provenance) is of the session's data. Raw: the part computes on the log as read.
// False when the section names other data than the open ones: it is not to be shown.
bool keepProvenance(const json& section, MainWindow& w, const char* key, bool raw) {
  Workspace* ws = w.workspace();
  if (section.is_null()) {
    ws->forgetResult(key);
    return true;
  }
  const auto stored = provenanceIn(section);
  return ws->recordResult(key, stored.value_or(ws->dataProvenance()), raw);
}

json captureModels(const MainWindow& w) {
  json list = json::array();
  // Physical models only: black-box estimates are recomputed from the data, not stored yet.
  for (const auto& m : w.workspace()->models()) {
    if (!m.model) continue;
    json j = modelToJson(m.name, *m.model, m.effects);
    if (m.fitRequest && m.fitRequest->provenance) j["provenance"] = provenanceToJson(*m.fitRequest->provenance);
    list.push_back(j);
  }
  return list;
}

void restoreModels(const json& section, MainWindow& w) {
  Workspace* ws = w.workspace();
  while (!ws->models().empty()) ws->removeModelDirect(static_cast<int>(ws->models().size()) - 1);
  for (const auto& m : section) {
    std::string why;
    auto spec = modelFromJson(m, &why);
    if (!spec) continue;  // validated when the file was read
    ModelEntry entry;
    entry.name = spec->name;
    entry.origin = ModelOrigin::Session;
    entry.model = spec->model;
    entry.effects = spec->effects;
    ws->insertModelDirect(static_cast<int>(ws->models().size()), entry);
  }
}

// The fits the Fit panel made, as requests a replay repeats; the SPA section comes with them.
// A physical request whose estimate is not in the model list (a hand-written session) is
// kept as read, so saving does not drop it; the window does not run the fit while opening.
constexpr const char* kUnattachedFits = "flexarmUnattachedFits";

json captureFits(const MainWindow& w) {
  json requests = json::array();
  for (const auto& m : w.workspace()->models()) {
    if (!m.fitRequest) continue;
    json request = fitRequestToJson(*m.fitRequest);
    if (m.polynomial) request["estimate"] = polynomialEstimateToJson(*m.polynomial);
    requests.push_back(request);
  }
  const QByteArray kept = w.property(kUnattachedFits).toByteArray();
  if (!kept.isEmpty())
    for (const auto& j : json::parse(kept.toStdString(), nullptr, false))
      requests.push_back(j);
  if (requests.empty()) return nullptr;
  return {{"nonparametric", true}, {"requests", requests}};
}

// Physical estimates come back with the model list: their requests are attached again. A
// black-box estimate comes back from the estimate stored with its request, so opening a
// session estimates nothing; a request without one (a hand-written session) is kept as read
// and replayed only by `flexarm run`.
void restoreFits(const json& section, MainWindow& w) {
  Workspace* ws = w.workspace();
  json unattached = json::array();
  std::optional<std::pair<FitRequest, int>> shown;  // the last fit with its estimate
  for (const auto& j : section["requests"]) {
    std::string why;
    auto request = fitRequestFromJson(j, &why);
    if (!request) continue;  // validated when the file was read
    auto shared = std::make_shared<const FitRequest>(*request);
    const QString name = QString::fromStdString(request->name);
    bool attached = false;
    for (std::size_t i = 0; i < ws->models().size() && !attached; ++i) {
      ModelEntry e = ws->models()[i];
      if (nameOf(e) != name || e.fitRequest) continue;
      e.fitRequest = shared;
      e.origin = ModelOrigin::Fit;
      ws->setModelDirect(static_cast<int>(i), e);
      attached = true;
      shown = {*request, static_cast<int>(i)};
    }
    if (attached) continue;
    std::optional<PolynomialModel> estimate;
    if (!request->physical() && j.contains("estimate"))
      estimate = polynomialEstimateFromJson(j["estimate"], *request, &why);
    if (!estimate) {
      unattached.push_back(j);
      continue;
    }
    ModelEntry e;
    e.name = request->name;
    e.origin = ModelOrigin::Fit;
    e.polynomial = std::make_shared<const PolynomialModel>(std::move(*estimate));
    e.fitRequest = shared;
    ws->insertModelDirect(static_cast<int>(ws->models().size()), e);
    shown = {*request, static_cast<int>(ws->models().size()) - 1};
  }
  w.setProperty(kUnattachedFits, unattached.empty() ? QByteArray()
                                                     : QByteArray::fromStdString(unattached.dump()));
  // The Fit panel shows the last fit as it was left: its choices, table and numbers.
  if (w.fitPanel()) {
    if (shown) w.fitPanel()->showStored(shown->first, shown->second);
    else w.fitPanel()->clearResult();
  }
}

void resetFits(MainWindow& w) {
  w.setProperty(kUnattachedFits, QByteArray());
  if (w.fitPanel()) w.fitPanel()->clearResult();
}

// The Discovery panel's last request and the summary of its result; restoring shows the
// stored result without running anything. A request saved without a result is kept as read
// (the window does not run discovery while opening) until the panel makes a result.
constexpr const char* kKeptDiscovery = "flexarmKeptDiscovery";

json captureDiscovery(const MainWindow& w) {
  if (!w.workspace()->hasResult("discovery")) return nullptr;  // none, or of other data
  const DiscoveryPanel* panel = w.discoveryPanel();
  if (panel && panel->lastRequest() && panel->result())
    return withProvenance({{"request", discoveryRequestToJson(*panel->lastRequest())},
                           {"result", discoveryResultToJson(*panel->result())}},
                          w, "discovery");
  const QByteArray kept = w.property(kKeptDiscovery).toByteArray();
  return kept.isEmpty() ? json(nullptr) : json::parse(kept.toStdString(), nullptr, false);
}

void resetDiscovery(MainWindow& w) {
  w.setProperty(kKeptDiscovery, QByteArray());
  keepProvenance(nullptr, w, "discovery", false);
  if (w.discoveryPanel()) w.discoveryPanel()->clearResult();
}

void restoreDiscovery(const json& section, MainWindow& w) {
  resetDiscovery(w);
  std::string why;
  auto request = discoveryRequestFromJson(section["request"], &why);
  std::optional<DiscoveryResult> result;
  if (section.contains("result") && section["result"].is_object())
    result = discoveryResultFromJson(section["result"], &why);
  if (w.discoveryPanel() && request && result) w.discoveryPanel()->showStored(*request, *result);
  else w.setProperty(kKeptDiscovery, QByteArray::fromStdString(section.dump()));
  if (!keepProvenance(section, w, "discovery", false)) resetDiscovery(w);  // of other data
}

// The LQG panel's design: parameters and where they came from, weights, saturation.
json captureLqg(const MainWindow& w) {
  const LqgPanel* panel = w.lqgPanel();
  if (!panel) return nullptr;
  LqgRequest r;
  r.source = panel->sourceText().toStdString();
  r.design = panel->options();
  r.saturationLimit = panel->analysisOptions().saturationLimit;
  r.taBandwidth = panel->analysisOptions().taBandwidth;
  return lqgRequestToJson(r);
}

void restoreLqg(const json& section, MainWindow& w) {
  std::string why;
  if (auto r = lqgRequestFromJson(section, &why); r && w.lqgPanel())
    w.lqgPanel()->setDesign(r->design, r->saturationLimit, QString::fromStdString(r->source));
}

// A session without a design opens with the seed's case (i) on Table 8.1.
void resetLqg(MainWindow& w) {
  if (w.lqgPanel()) w.lqgPanel()->setDesign(LqgOptions::seedCaseI(), 0.0, w.lqgPanel()->tableSourceText());
}

// The Diagnosis panel's request (its reference log joins the session's logs under this name)
// and the summary of its result; restoring takes the request over without running it.
constexpr const char* kDiagnosisReference = "diagnosis_reference";

json captureDiagnosis(const MainWindow& w) {
  const DiagnosisPanel* panel = w.diagnosisPanel();
  if (!panel || !w.workspace()->hasResult("diagnosis")) return nullptr;
  const auto request = panel->sessionRequest(kDiagnosisReference);
  if (!request) return nullptr;
  json section = {{"request", diagnosisRequestToJson(*request)}};
  if (const DiagnosisRun* run = panel->lastRun(); run && run->ok()) {
    section["result"] = diagnosisResultJson(run->result);
    section = withProvenance(section, w, "diagnosis");
  } else if (!panel->storedResult().is_null()) {  // taken over from a session, not run again
    section["result"] = panel->storedResult();
    section = withProvenance(section, w, "diagnosis");
  }
  return section;
}

std::vector<LogReference> diagnosisLogs(const MainWindow& w) {
  const DiagnosisPanel* panel = w.diagnosisPanel();
  if (!panel || panel->referenceLogPath().isEmpty() || !panel->sessionRequest(kDiagnosisReference))
    return {};
  LogReference l;
  l.name = kDiagnosisReference;
  l.path = panel->referenceLogPath().toStdString();
  return {l};
}

void resetDiagnosis(MainWindow& w) {
  keepProvenance(nullptr, w, "diagnosis", true);
  if (w.diagnosisPanel()) w.diagnosisPanel()->clearResult();
}

void restoreDiagnosis(const json& section, MainWindow& w) {
  std::string why;
  const auto request = diagnosisRequestFromJson(section["request"], &why);
  if (!request || !w.diagnosisPanel()) return;
  const QString path = request->referenceLog.empty() || !w.sessionController()
                           ? QString()
                           : w.sessionController()->sessionLogPath(request->referenceLog);
  w.diagnosisPanel()->setRequest(*request, path, section.contains("result") ? section["result"] : json());
  if (!keepProvenance(section, w, "diagnosis", true)) resetDiagnosis(w);  // of another log
}


// The Recursive panel's runs (the overlaid previous one and the current one): each request
// with the summary of its result when it ran to the end. Opening a session sets the panel's
// controls from the last request and runs nothing; the runs are kept as read until the panel
// makes a run of its own.
constexpr const char* kKeptRecursive = "flexarmKeptRecursive";

json captureRecursive(const MainWindow& w) {
  if (!w.workspace()->hasResult("recursive")) return nullptr;
  const RecursivePanel* panel = w.recursivePanel();
  json runs = json::array();
  if (panel)
    for (const auto* run : panel->runs()) {
      json entry = {{"request", recursiveRequestToJson(run->request)}};
      if (run->result) entry["result"] = recursiveResultToJson(*run->result);
      runs.push_back(entry);
    }
  if (!runs.empty()) return withProvenance({{"runs", runs}}, w, "recursive");
  const QByteArray kept = w.property(kKeptRecursive).toByteArray();
  return kept.isEmpty() ? json(nullptr) : json::parse(kept.toStdString(), nullptr, false);
}

void resetRecursive(MainWindow& w) {
  w.setProperty(kKeptRecursive, QByteArray());
  keepProvenance(nullptr, w, "recursive", true);
  if (w.recursivePanel()) w.recursivePanel()->clearRuns();
}

void restoreRecursive(const json& section, MainWindow& w) {
  resetRecursive(w);
  w.setProperty(kKeptRecursive, QByteArray::fromStdString(section.dump()));
  std::string why;
  if (!section["runs"].empty() && w.recursivePanel())
    if (auto q = recursiveRequestFromJson(section["runs"].back()["request"], &why)) {
      w.recursivePanel()->setRequest(*q);
      // The last run's end and final estimates, as stored: nothing runs while opening.
      const json& last = section["runs"].back();
      if (last.contains("result") && last["result"].is_object()) {
        const json& r = last["result"];
        QStringList finals;
        if (r.contains("final") && r["final"].is_object())
          for (const auto& [name, value] : r["final"].items())
            if (value.is_number())
              finals << QString("%1 = %2").arg(QString::fromStdString(name)).arg(value.get<double>(), 0, 'g', 5);
        w.recursivePanel()->showStored(
            QObject::tr("From the session: %1 (%2 after %3 samples); final %4. Play runs it again with its plots.")
                .arg(QString::fromStdString(q->label.empty() ? std::string("the last run") : q->label),
                     QString::fromStdString(r.value("termination", std::string("?"))))
                .arg(r.value("samples", 0))
                .arg(finals.isEmpty() ? QObject::tr("estimates not stored") : finals.join(", ")));
      }
    }
  if (!keepProvenance(section, w, "recursive", true)) resetRecursive(w);  // of another log
}

json captureView(const MainWindow& w) {
  return {{"window_state", w.saveState().toBase64().toStdString()},
          {"layout", PanelDocks::toString(w.docks()->layout())},
          {"selected_model", w.modelPanel() ? w.modelPanel()->currentIndex() : -1}};
}

// The docks come back as saved when they were saved for a screen of the same kind (a
// laptop's layout on a large screen or the reverse keeps the layout chosen for this one).
void restoreView(const json& section, MainWindow& w) {
  const bool sameScreen = !section.contains("layout") || !section["layout"].is_string() ||
                          section["layout"].get<std::string>() == PanelDocks::toString(w.docks()->layout());
  if (sameScreen && section.contains("window_state") && section["window_state"].is_string())
    w.restoreState(QByteArray::fromBase64(QByteArray::fromStdString(section["window_state"].get<std::string>())));
  if (w.modelPanel() && section.contains("selected_model") && section["selected_model"].is_number_integer())
    w.modelPanel()->selectModel(section["selected_model"].get<int>());
}

}  // namespace

const std::vector<WindowSessionPart>& windowSessionParts() {
  // In the order of core sessionParts(); later capabilities add their pair here.
  static const std::vector<WindowSessionPart> kParts = {
      {"models", &captureModels, &restoreModels},
      {"fits", &captureFits, &restoreFits, &resetFits},
      {"discovery", &captureDiscovery, &restoreDiscovery, &resetDiscovery},
      {"lqg", &captureLqg, &restoreLqg, &resetLqg},
      {"diagnosis", &captureDiagnosis, &restoreDiagnosis, &resetDiagnosis, &diagnosisLogs},
      {"recursive", &captureRecursive, &restoreRecursive, &resetRecursive},
      {"view", &captureView, &restoreView},
  };
  return kParts;
}

}  // namespace flexarm
