#include "app/session_parts.h"

#include <QByteArray>

#include "app/main_window.h"
#include "core/session/model_json.h"
#include "widgets/model_panel.h"
#include "widgets/workspace.h"

namespace flexarm {
namespace {

using nlohmann::json;

json captureModels(const MainWindow& w) {
  json list = json::array();
  // Physical models only: black-box estimates are recomputed from the data, not stored yet.
  for (const auto& m : w.workspace()->models())
    if (m.model) list.push_back(modelToJson(m.name.toStdString(), *m.model, m.effects));
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

const std::vector<WindowSessionPart>& windowSessionParts() {
  // In the order of core sessionParts(); later capabilities add their pair here.
  static const std::vector<WindowSessionPart> kParts = {
      {"models", &captureModels, &restoreModels},
      {"view", &captureView, &restoreView},
  };
  return kParts;
}

}  // namespace flexarm
