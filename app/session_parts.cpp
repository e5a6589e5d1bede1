#include "app/session_parts.h"

#include <QByteArray>
#include <QVariant>

#include "app/main_window.h"
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
#include "widgets/lqg_panel.h"
#include "widgets/model_panel.h"
#include "widgets/recursive_panel.h"
#include "widgets/workspace.h"

namespace flexarm {
namespace {

using nlohmann::json;

// The data of the result a panel made last, as the window recorded it (recordProvenance).
QByteArray provenanceProperty(const char* key) { return QByteArray("flexarmProvenance_") + key; }

json withProvenance(json section, const MainWindow& w, const char* key) {
  const QByteArray p = w.property(provenanceProperty(key).constData()).toByteArray();
  if (!p.isEmpty() && section.is_object() && !section.contains("provenance"))
    section["provenance"] = json::parse(p.toStdString(), nullptr, false);
  return section;
}

// A restored section's provenance becomes the window's record, so saving again keeps it.
void keepProvenance(const json& section, MainWindow& w, const char* key) {
  w.setProperty(provenanceProperty(key).constData(), section.is_object() && section.contains("provenance")
                                             ? QByteArray::fromStdString(section["provenance"].dump())
                                             : QByteArray());
}

json captureModels(const MainWindow& w) {
  json list = json::array();
  // Physical models only: black-box estimates are recomputed from the data, not stored yet.
  for (const auto& m : w.workspace()->models()) {
    if (!m.model) continue;
    json j = modelToJson(m.name.toStdString(), *m.model, m.effects);
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
    entry.name = QString::fromStdString(spec->name);
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
  for (const auto& j : section["requests"]) {
    std::string why;
    auto request = fitRequestFromJson(j, &why);
    if (!request) continue;  // validated when the file was read
    auto shared = std::make_shared<const FitRequest>(*request);
    const QString name = QString::fromStdString(request->name);
    bool attached = false;
    for (std::size_t i = 0; i < ws->models().size() && !attached; ++i) {
      ModelEntry e = ws->models()[i];
      if (e.name != name || e.fitRequest) continue;
      e.fitRequest = shared;
      ws->setModelDirect(static_cast<int>(i), e);
      attached = true;
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
    e.name = name;
    e.polynomial = std::make_shared<const PolynomialModel>(std::move(*estimate));
    e.fitRequest = shared;
    ws->insertModelDirect(static_cast<int>(ws->models().size()), e);
  }
  w.setProperty(kUnattachedFits, unattached.empty() ? QByteArray()
                                                     : QByteArray::fromStdString(unattached.dump()));
}

// The Discovery panel's last request and the summary of its result; restoring shows the
// stored result without running anything. A request saved without a result is kept as read
// (the window does not run discovery while opening) until the panel makes a result.
constexpr const char* kKeptDiscovery = "flexarmKeptDiscovery";

json captureDiscovery(const MainWindow& w) {
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
  keepProvenance(nullptr, w, "discovery");
  if (w.discoveryPanel()) w.discoveryPanel()->clearResult();
}

void restoreDiscovery(const json& section, MainWindow& w) {
  resetDiscovery(w);
  keepProvenance(section, w, "discovery");
  std::string why;
  auto request = discoveryRequestFromJson(section["request"], &why);
  std::optional<DiscoveryResult> result;
  if (section.contains("result") && section["result"].is_object())
    result = discoveryResultFromJson(section["result"], &why);
  if (w.discoveryPanel() && request && result) w.discoveryPanel()->showStored(*request, *result);
  else w.setProperty(kKeptDiscovery, QByteArray::fromStdString(section.dump()));
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
  if (!panel) return nullptr;
  const auto request = panel->sessionRequest(kDiagnosisReference);
  if (!request) return nullptr;
  json section = {{"request", diagnosisRequestToJson(*request)}};
  if (const DiagnosisRun* run = panel->lastRun(); run && run->ok()) {
    section["result"] = diagnosisResultJson(run->result);
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

void restoreDiagnosis(const json& section, MainWindow& w) {
  keepProvenance(section, w, "diagnosis");
  std::string why;
  const auto request = diagnosisRequestFromJson(section["request"], &why);
  if (!request || !w.diagnosisPanel()) return;
  const QString path = request->referenceLog.empty() || !w.sessionController()
                           ? QString()
                           : w.sessionController()->sessionLogPath(request->referenceLog);
  w.diagnosisPanel()->setRequest(*request, path);
}

void resetDiagnosis(MainWindow& w) {
  keepProvenance(nullptr, w, "diagnosis");
  if (w.diagnosisPanel()) w.diagnosisPanel()->clearResult();
}

// The Recursive panel's runs (the overlaid previous one and the current one): each request
// with the summary of its result when it ran to the end. Opening a session sets the panel's
// controls from the last request and runs nothing; the runs are kept as read until the panel
// makes a run of its own.
constexpr const char* kKeptRecursive = "flexarmKeptRecursive";

json captureRecursive(const MainWindow& w) {
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
  keepProvenance(nullptr, w, "recursive");
  if (w.recursivePanel()) w.recursivePanel()->clearRuns();
}

void restoreRecursive(const json& section, MainWindow& w) {
  resetRecursive(w);
  keepProvenance(section, w, "recursive");
  w.setProperty(kKeptRecursive, QByteArray::fromStdString(section.dump()));
  std::string why;
  if (!section["runs"].empty() && w.recursivePanel())
    if (auto q = recursiveRequestFromJson(section["runs"].back()["request"], &why))
      w.recursivePanel()->setRequest(*q);
}

json captureView(const MainWindow& w) {
  return {{"window_state", w.saveState().toBase64().toStdString()},
          {"selected_model", w.modelPanel() ? w.modelPanel()->currentIndex() : -1}};
}

void restoreView(const json& section, MainWindow& w) {
  if (section.contains("window_state") && section["window_state"].is_string())
    w.restoreState(QByteArray::fromBase64(QByteArray::fromStdString(section["window_state"].get<std::string>())));
  if (w.modelPanel() && section.contains("selected_model") && section["selected_model"].is_number_integer())
    w.modelPanel()->selectModel(section["selected_model"].get<int>());
}

}  // namespace

void recordProvenance(MainWindow& window, const char* key) {
  window.setProperty(provenanceProperty(key).constData(),
                     QByteArray::fromStdString(provenanceToJson(window.workspace()->dataProvenance()).dump()));
}

const std::vector<WindowSessionPart>& windowSessionParts() {
  // In the order of core sessionParts(); later capabilities add their pair here.
  static const std::vector<WindowSessionPart> kParts = {
      {"models", &captureModels, &restoreModels},
      {"fits", &captureFits, &restoreFits},
      {"discovery", &captureDiscovery, &restoreDiscovery, &resetDiscovery},
      {"lqg", &captureLqg, &restoreLqg, &resetLqg},
      {"diagnosis", &captureDiagnosis, &restoreDiagnosis, &resetDiagnosis, &diagnosisLogs},
      {"recursive", &captureRecursive, &restoreRecursive, &resetRecursive},
      {"view", &captureView, &restoreView},
  };
  return kParts;
}

}  // namespace flexarm
