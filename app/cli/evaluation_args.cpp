#include "app/cli/evaluation_args.h"

#include <filesystem>
#include <ostream>

#include "app/cli/log_args.h"
#include "app/cli/model_args.h"
#include "core/session/session_models.h"
#include "core/session/replay.h"

namespace flexarm::cli {

std::vector<std::string> evaluationValuedOptions() {
  std::vector<std::string> v = logReadOptionNames();
  for (const auto& o : modelValuedOptions()) v.push_back(o);
  for (const char* o : {"session", "model-file", "effect", "decimation", "estimation", "validation", "models"})
    v.push_back(o);
  return v;
}

std::vector<std::string> evaluationFlagOptions() {
  std::vector<std::string> v = modelFlagOptions();
  v.push_back("json");
  v.push_back("help");
  return v;
}

std::string evaluationOptionsHelp() {
  return std::string(
             "Data (one of):\n"
             "  LOG                   the log (ranges from --estimation, --validation, else its\n"
             "                        metadata)\n"
             "  --session FILE        the session's analysed log (read and preprocessed as the\n"
             "                        session says), its ranges and its model list\n"
             "  --estimation A:B, --validation A:B   the ranges in seconds (override)\n\n"
             "Models (any of; all together in this order):\n"
             "  the session's model list (--session), its estimates at the rate they were fitted\n"
             "  --model-file FILE     a physical model: `flexarm fit --json` or a model as sessions\n"
             "                        store it (repeatable)\n"
             "  --model STRUCTURE     one model given by its options (with --param, --effect)\n"
             "  --effect NAME[:V1[,V2]]  an effect of that model (repeatable)\n"
             "  --decimation N        the decimation the physical models of files and options were\n"
             "                        fitted at (default 1: the log's rate)\n"
             "  --models A,B          only the models with these names\n\n") +
         modelOptionsHelp() + "\n" + logReadOptionsHelp();
}

namespace {

int fromSession(const std::string& path, EvaluationInput& in, const std::string& verb, std::ostream& err) {
  const SessionParseResult loaded = loadSession(path);
  if (!loaded.ok) {
    err << "flexarm " << verb << ": " << loaded.message << "\n";
    return kExitBadInput;
  }
  const PreparedSession prepared = prepareSession(loaded.session, path);
  if (!prepared.ok) {
    err << "flexarm " << verb << ": " << prepared.message << "\n";
    return kExitBadInput;
  }
  in.data.log = std::make_shared<const IdData>(prepared.logs.front().data);
  in.data.name = std::filesystem::path(prepared.logs.front().path).filename().string();
  in.data.estimation = loaded.session.estimation;
  in.data.validation = loaded.session.validation;
  const ModelList list = modelListOf(loaded.session);
  for (const auto& e : list.entries()) in.models.push_back(e.evaluated());
  return kExitOk;
}

}  // namespace

int evaluationInput(ArgParser& args, const std::string& verb, EvaluationInput& in, std::ostream& err) {
  const std::string pre = "flexarm " + verb + ": ";
  auto usage = [&](const std::string& why) {
    err << pre << why << "\n";
    return kExitUsage;
  };
  const auto session = args.value("session");
  if (args.positional().size() > 1) return usage("one LOG at most");
  if (session && !args.positional().empty()) return usage("give either LOG or --session, not both");
  if (!session && args.positional().empty()) return usage("no data: give LOG or --session FILE");
  if (session) {
    if (const int code = fromSession(*session, in, verb, err); code != kExitOk) return code;
  } else {
    auto read = logReadOptions(args, err);
    if (!read) return kExitUsage;
    auto log = loadLog(args.positional().front(), *read, err);
    if (!log) return kExitBadInput;
    if (log->estimationRange && !log->estimationRange->empty()) in.data.estimation = secondsOf(*log, *log->estimationRange);
    if (log->validationRange && !log->validationRange->empty()) in.data.validation = secondsOf(*log, *log->validationRange);
    in.data.name = std::filesystem::path(args.positional().front()).filename().string();
    in.data.log = std::make_shared<const IdData>(std::move(*log));
  }
  for (const auto& [option, target] : {std::pair{"estimation", &in.data.estimation},
                                       std::pair{"validation", &in.data.validation}}) {
    const auto text = args.value(option);
    if (!text) continue;
    std::string why;
    auto r = secondsRangeFromText(*text, &why);
    if (!r) return usage(std::string("--") + option + ": " + why);
    if (samplesIn(*in.data.log, *r).empty())
      return usage(std::string("--") + option + " " + *text + " s holds no samples of the log");
    *target = r;
  }
  int decimation = 1;
  if (args.value("decimation") && !args.integer("decimation", decimation, 1, 1000)) return usage(args.error());
  for (const auto& file : args.values("model-file")) {
    std::string why;
    auto model = modelFromFile(file, &why);
    if (!model) {
      err << pre << file << ": " << why << "\n";
      return kExitBadInput;
    }
    EvaluatedModel m;
    m.name = std::filesystem::path(file).stem().string();
    m.physical = std::shared_ptr<const PhysicalModel>(std::move(model));
    m.decimation = decimation;
    in.models.push_back(std::move(m));
  }
  if (args.value("model")) {
    auto model = modelFromArgs(args, verb, err);
    if (!model) return kExitUsage;
    EvaluatedModel m;
    m.name = model->structureName();
    for (const auto& spec : args.values("effect")) {
      std::string why;
      auto e = parseEffect(spec, &why);
      if (!e) return usage("--effect " + spec + ": " + why);
      m.effects.push_back(*e);
    }
    m.physical = std::shared_ptr<const PhysicalModel>(std::move(model));
    m.decimation = decimation;
    in.models.push_back(std::move(m));
  } else if (!args.values("effect").empty()) {
    return usage("--effect needs --model");
  }
  if (const auto names = args.value("models")) return selectModels(in, splitList(*names), verb, err) ? kExitOk : kExitUsage;
  return kExitOk;
}

bool selectModels(EvaluationInput& in, const std::vector<std::string>& names, const std::string& verb,
                  std::ostream& err) {
  if (names.empty()) return true;
  std::vector<EvaluatedModel> chosen;
  for (const auto& name : names) {
    bool found = false;
    for (const auto& m : in.models)
      if (m.name == name) {
        chosen.push_back(m);
        found = true;
        break;
      }
    if (!found) {
      std::string known;
      for (const auto& m : in.models) known += (known.empty() ? "" : ", ") + m.name;
      err << "flexarm " << verb << ": no model '" << name << "' (models: " << (known.empty() ? "none" : known) << ")\n";
      return false;
    }
  }
  in.models = std::move(chosen);
  return true;
}

}  // namespace flexarm::cli
