#include "deploy/cli/run_flags.h"

#include <google/protobuf/descriptor.h>
#include <google/protobuf/message.h>

#include "absl/flags/flag.h"
#include "absl/flags/reflection.h"
#include "absl/strings/numbers.h"
#include "absl/strings/str_cat.h"
#include "absl/strings/str_format.h"
#include "absl/strings/str_join.h"
#include "absl/strings/str_split.h"
#include "actor/evaluation_config.h"
#include "common/nn/network_config.h"
#include "deploy/cli/command_line.h"
#include "deploy/run/run_config.h"
#include "learner/algorithms/algorithm_config.h"
#include "learner/exploration/ex2_config.h"

// The run flags that are no run-config field. The fields' own flags are
// declared from proto/run_config.proto (its `flag` option: RunSettingFlags),
// --env, --envs and --seed are the shared flags (deploy/cli/shared_flags).
// Every default is ResolveRunConfig's (see RunFlagDefaults): a flag's own
// default below is never read, since only given flags enter the config.
// The algorithms' names come from their registry.
ABSL_FLAG(std::string, algo, "",
          absl::StrCat(absl::StrJoin(vantage::AlgorithmNames(), " | "),
                       " (a --config file's settings of another algorithm "
                       "are dropped)"));
ABSL_FLAG(std::string, config, "",
          "a JSON run config (as a run directory's config.json); the flags "
          "given override it");
ABSL_FLAG(std::string, run_dir, "",
          "directory for config.json, progress.csv and checkpoints/");
ABSL_FLAG(std::string, resume, "",
          "continue the run in this directory from its newest checkpoint");
ABSL_FLAG(bool, resume_if_exists, false,
          "with --run_dir: a directory already holding a run made with the "
          "same settings continues it from its newest checkpoint (one that "
          "never checkpointed starts over); other settings are refused. For "
          "commands a scheduler repeats (requeued jobs, restarted pods)");
ABSL_FLAG(std::string, exploration, "",
          "none | ex2 (EX2's exemplar-model novelty bonus added to the "
          "rewards on the learner; its settings are the --ex2_ flags)");

namespace vantage {
namespace {

using google::protobuf::Descriptor;
using google::protobuf::FieldDescriptor;
using google::protobuf::Message;

// One flag of a run-config field: `field` of the section `section`
// (a RunConfig message field) or of RunConfig itself (section null), or of
// the message `group` inside the section (an exploration method's).
struct RunFlag {
  std::string name;
  const FieldDescriptor* section = nullptr;
  const FieldDescriptor* field = nullptr;
  const FieldDescriptor* group = nullptr;
  bool algorithm() const {
    return section != nullptr && section->containing_oneof() != nullptr;
  }
  // The field's `flag` option: its help line; empty for the fields whose
  // flags are shared absl flags (--env, --envs, --seed).
  const std::string& help() const {
    return field->options().GetExtension(pb::flag);
  }
};

const std::vector<RunFlag>& RunFlags() {
  static const auto* flags = [] {
    auto* all = new std::vector<RunFlag>;
    const Descriptor* run = pb::RunConfig::descriptor();
    for (int i = 0; i < run->field_count(); ++i) {
      const FieldDescriptor* section = run->field(i);
      if (section->message_type() == nullptr) {
        all->push_back({section->name(), nullptr, section});
        continue;
      }
      const bool algorithm = section->containing_oneof() != nullptr;
      const Descriptor* fields = section->message_type();
      for (int j = 0; j < fields->field_count(); ++j) {
        const FieldDescriptor* field = fields->field(j);
        if (field->message_type() != nullptr) {
          const Descriptor* group = field->message_type();
          for (int k = 0; k < group->field_count(); ++k) {
            all->push_back(
                {absl::StrCat(field->name(), "_", group->field(k)->name()),
                 section, group->field(k), field});
          }
          continue;
        }
        all->push_back({algorithm
                            ? absl::StrCat(section->name(), "_", field->name())
                            : field->name(),
                        section, field});
      }
    }
    return all;
  }();
  return *flags;
}

const RunFlag* FindRunFlag(const std::string& name) {
  for (const RunFlag& flag : RunFlags()) {
    if (flag.name == name) return &flag;
  }
  return nullptr;
}

// The message holding the flag's field, or null when its section is absent.
const Message* Holder(const pb::RunConfig& config, const RunFlag& flag) {
  if (flag.section == nullptr) return &config;
  const auto* reflection = config.GetReflection();
  if (!reflection->HasField(config, flag.section)) return nullptr;
  const Message& section = reflection->GetMessage(config, flag.section);
  if (flag.group == nullptr) return &section;
  if (!section.GetReflection()->HasField(section, flag.group)) return nullptr;
  return &section.GetReflection()->GetMessage(section, flag.group);
}

std::string FieldText(const Message& message, const FieldDescriptor& field) {
  const auto* reflection = message.GetReflection();
  if (field.is_repeated()) {
    std::vector<std::string> values;
    for (int i = 0; i < reflection->FieldSize(message, &field); ++i) {
      values.push_back(
          absl::StrCat(reflection->GetRepeatedInt64(message, &field, i)));
    }
    return absl::StrJoin(values, ",");
  }
  if (!reflection->HasField(message, &field)) return "";
  switch (field.cpp_type()) {
    case FieldDescriptor::CPPTYPE_STRING:
      return reflection->GetString(message, &field);
    case FieldDescriptor::CPPTYPE_BOOL:
      return reflection->GetBool(message, &field) ? "true" : "false";
    case FieldDescriptor::CPPTYPE_DOUBLE:
      return absl::StrFormat("%g", reflection->GetDouble(message, &field));
    case FieldDescriptor::CPPTYPE_INT32:
      return absl::StrCat(reflection->GetInt32(message, &field));
    case FieldDescriptor::CPPTYPE_INT64:
      return absl::StrCat(reflection->GetInt64(message, &field));
    case FieldDescriptor::CPPTYPE_UINT64:
      return absl::StrCat(reflection->GetUInt64(message, &field));
    default:
      return "?";
  }
}

// Parses `text` as an integer of type T for `set`; `bad` words the error.
template <typename T, typename Bad, typename Set>
absl::Status SetInteger(const std::string& text, const Bad& bad,
                        const Set& set) {
  T value = 0;
  if (!absl::SimpleAtoi(text, &value)) return bad("is not an integer");
  set(value);
  return absl::OkStatus();
}

// Sets the flag's field from the flag's value as absl prints it.
absl::Status SetField(const RunFlag& flag, const std::string& text,
                      pb::RunConfig& config) {
  Message* message =
      flag.section == nullptr
          ? &config
          : config.GetReflection()->MutableMessage(&config, flag.section);
  if (flag.group != nullptr) {
    message = message->GetReflection()->MutableMessage(message, flag.group);
  }
  const auto* reflection = message->GetReflection();
  const FieldDescriptor* field = flag.field;
  auto bad = [&](absl::string_view what) {
    return absl::InvalidArgumentError(
        absl::StrCat("--", flag.name, " '", text, "' ", what));
  };
  if (field->is_repeated()) {
    reflection->ClearField(message, field);
    for (absl::string_view entry :
         absl::StrSplit(text, ',', absl::SkipEmpty())) {
      int64_t value = 0;
      if (!absl::SimpleAtoi(entry, &value)) {
        return absl::InvalidArgumentError(absl::StrCat(
            "--", flag.name, " entry '", entry, "' is not an integer"));
      }
      reflection->AddInt64(message, field, value);
    }
    return absl::OkStatus();
  }
  switch (field->cpp_type()) {
    case FieldDescriptor::CPPTYPE_STRING:
      reflection->SetString(message, field, text);
      return absl::OkStatus();
    case FieldDescriptor::CPPTYPE_BOOL: {
      bool value = false;
      if (!absl::SimpleAtob(text, &value)) return bad("is not a boolean");
      reflection->SetBool(message, field, value);
      return absl::OkStatus();
    }
    case FieldDescriptor::CPPTYPE_DOUBLE: {
      double value = 0;
      if (!absl::SimpleAtod(text, &value)) return bad("is not a number");
      reflection->SetDouble(message, field, value);
      return absl::OkStatus();
    }
    case FieldDescriptor::CPPTYPE_INT32:
      return SetInteger<int32_t>(text, bad, [&](int32_t value) {
        reflection->SetInt32(message, field, value);
      });
    case FieldDescriptor::CPPTYPE_INT64:
      return SetInteger<int64_t>(text, bad, [&](int64_t value) {
        reflection->SetInt64(message, field, value);
      });
    case FieldDescriptor::CPPTYPE_UINT64:
      return SetInteger<uint64_t>(text, bad, [&](uint64_t value) {
        reflection->SetUInt64(message, field, value);
      });
    default:
      return bad("has a type no flag reads");
  }
}

pb::RunConfig Resolved(const std::string& algo, const std::string& mode,
                       const std::string& exploration = "none") {
  pb::RunConfig given;
  if (!algo.empty()) (void)SelectAlgorithm(algo, given);
  (void)SelectExploration(exploration, given);
  if (!mode.empty()) given.set_mode(mode);
  // The defaults resolve by construction; a failure is a programming error
  // that the help test catches as an empty default.
  absl::StatusOr<pb::RunConfig> resolved = ResolveRunConfig(given);
  return resolved.ok() ? *resolved : pb::RunConfig();
}

}  // namespace

std::string RunConfigFieldText(const pb::RunConfig& config,
                               const std::string& flag) {
  if (flag == "algo") return AlgorithmNameOf(config);
  if (flag == "exploration") return ExplorationNameOf(config);
  const RunFlag* run_flag = FindRunFlag(flag);
  if (run_flag == nullptr) return "";
  const Message* holder = Holder(config, *run_flag);
  return holder == nullptr ? "" : FieldText(*holder, *run_flag->field);
}

std::vector<std::string> RunSettingNames() {
  std::vector<std::string> names = {"algo", "exploration"};
  for (const RunFlag& flag : RunFlags()) names.push_back(flag.name);
  return names;
}

std::vector<std::string> RunFlagNames(bool with_mode) {
  std::vector<std::string> names;
  bool exploration_named = false;
  for (const RunFlag& flag : RunFlags()) {
    if (flag.group != nullptr && !exploration_named) {
      names.push_back("exploration");
      exploration_named = true;
    }
    if (flag.name == "mode") {
      if (with_mode) names.push_back(flag.name);
      names.push_back("algo");
      continue;
    }
    names.push_back(flag.name);
  }
  for (const char* name : {"config", "run_dir", "resume", "resume_if_exists"}) {
    names.push_back(name);
  }
  return names;
}

std::map<std::string, std::string> RunFlagDefaults(bool with_mode) {
  const pb::RunConfig standard = Resolved("", "");
  const pb::RunConfig local = Resolved("", "local");
  std::map<std::string, pb::RunConfig> by_algorithm;
  for (const std::string& algo : AlgorithmNames()) {
    by_algorithm[algo] = Resolved(algo, "");
  }
  std::map<std::string, std::string> defaults;
  defaults["algo"] = AlgorithmNameOf(standard);
  defaults["exploration"] = ExplorationNameOf(standard);
  std::map<std::string, pb::RunConfig> by_exploration;
  for (const std::string& method : ExplorationNames()) {
    by_exploration[method] = Resolved("", "", method);
  }
  for (const RunFlag& flag : RunFlags()) {
    if (flag.group != nullptr) {
      // Only its own method reads it.
      defaults[flag.name] =
          RunConfigFieldText(by_exploration[flag.group->name()], flag.name);
      continue;
    }
    if (flag.algorithm()) {
      // Only its own algorithm reads it.
      defaults[flag.name] =
          RunConfigFieldText(by_algorithm[flag.section->name()], flag.name);
      continue;
    }
    std::string text = RunConfigFieldText(standard, flag.name);
    // Varying a flag shows nothing about its own default.
    if (flag.name != "mode") {
      std::vector<std::string> values;
      bool differs = false;
      for (const auto& [algo, config] : by_algorithm) {
        const std::string value = RunConfigFieldText(config, flag.name);
        differs = differs || value != text;
        values.push_back(absl::StrCat(algo, ": ", value));
      }
      if (differs) text = absl::StrJoin(values, "; ");
      const std::string in_local = RunConfigFieldText(local, flag.name);
      if (with_mode && in_local != RunConfigFieldText(standard, flag.name)) {
        absl::StrAppend(&text, " (--mode=local: ",
                        in_local.empty() ? "unused" : in_local, ")");
      }
    }
    defaults[flag.name] = text;
  }
  // A feed-forward run's config holds no core settings: what a core takes.
  const NetworkConfig network;
  defaults["core"] = CoreName(network.core);
  defaults["core_size"] = absl::StrCat(network.core_size);
  defaults["seq_len"] = absl::StrCat(network.seq_len);
  // Nor does a run's config without evaluations hold their settings.
  const EvaluationConfig evaluation;
  defaults["eval_every"] = absl::StrCat(evaluation.every);
  defaults["eval_episodes"] = absl::StrCat(evaluation.episodes);
  return defaults;
}

absl::StatusOr<RunRequest> RunRequestFromSettings(
    const std::vector<std::pair<std::string, std::string>>& settings) {
  RunRequest request;
  for (const auto& [name, text] : settings) {
    if (name != "algo") continue;
    request.algo = text;
    request.given_flags.push_back("algo");
    if (absl::Status status = SelectAlgorithm(request.algo, request.flags);
        !status.ok()) {
      return absl::InvalidArgumentError(
          absl::StrCat("--algo: ", status.message()));
    }
  }
  for (const auto& [name, text] : settings) {
    if (name != "exploration") continue;
    request.exploration = text;
    request.given_flags.push_back("exploration");
    if (absl::Status status = SelectExploration(text, request.flags);
        !status.ok()) {
      return absl::InvalidArgumentError(
          absl::StrCat("--exploration: ", status.message()));
    }
  }
  const RunFlag* algorithm_flag = nullptr;
  for (const auto& [name, text] : settings) {
    if (name == "algo" || name == "exploration") continue;
    const RunFlag* flag = FindRunFlag(name);
    if (flag == nullptr) {
      return absl::InvalidArgumentError(
          absl::StrCat("'", name, "' is not a run setting; the run flags: ",
                       absl::StrJoin(RunSettingNames(), ", ")));
    }
    request.given_flags.push_back(name);
    if (flag->algorithm()) {
      const std::string& algo = flag->section->name();
      if (!request.algo.empty() && algo != request.algo) {
        return absl::InvalidArgumentError(
            absl::StrCat("--", name, " is a ", algo,
                         " setting; this run's --algo is ", request.algo));
      }
      if (algorithm_flag != nullptr &&
          algorithm_flag->section != flag->section) {
        return absl::InvalidArgumentError(absl::StrCat(
            "--", algorithm_flag->name, " and --", name,
            " are settings of two algorithms; choose one with --algo"));
      }
      algorithm_flag = flag;
    }
    if (flag->group != nullptr && !request.exploration.empty() &&
        request.exploration != flag->group->name()) {
      return absl::InvalidArgumentError(
          absl::StrCat("--", name, " is a setting of ", flag->group->name(),
                       "; this run's --exploration is ", request.exploration));
    }
    if (absl::Status status = SetField(*flag, text, request.flags);
        !status.ok()) {
      return status;
    }
  }
  return request;
}

std::vector<DeclaredFlag> RunSettingFlags() {
  std::vector<DeclaredFlag> declared;
  for (const RunFlag& flag : RunFlags()) {
    if (flag.help().empty()) continue;
    declared.push_back(
        {flag.name, flag.help(),
         flag.field->cpp_type() == FieldDescriptor::CPPTYPE_BOOL &&
             !flag.field->is_repeated(),
         [&flag](const std::string& text) {
           pb::RunConfig scratch;
           return SetField(flag, text, scratch);
         }});
  }
  return declared;
}

absl::StatusOr<RunRequest> RunRequestFromFlags() {
  std::vector<std::pair<std::string, std::string>> settings;
  if (FlagGiven("algo")) {
    settings.emplace_back("algo", absl::GetFlag(FLAGS_algo));
  }
  if (FlagGiven("exploration")) {
    settings.emplace_back("exploration", absl::GetFlag(FLAGS_exploration));
  }
  for (const RunFlag& flag : RunFlags()) {
    if (std::optional<std::string> value = DeclaredFlagValue(flag.name)) {
      settings.emplace_back(flag.name, *value);
      continue;
    }
    if (!FlagGiven(flag.name)) continue;
    const absl::CommandLineFlag* absl_flag =
        absl::FindCommandLineFlag(flag.name);
    if (absl_flag == nullptr) {
      return absl::InternalError(
          absl::StrCat("run-config field ", flag.name, " has no flag"));
    }
    settings.emplace_back(flag.name, absl_flag->CurrentValue());
  }
  absl::StatusOr<RunRequest> request = RunRequestFromSettings(settings);
  if (!request.ok()) return request.status();
  request->config_file = absl::GetFlag(FLAGS_config);
  request->run_dir = absl::GetFlag(FLAGS_run_dir);
  request->resume = absl::GetFlag(FLAGS_resume);
  request->resume_if_exists = absl::GetFlag(FLAGS_resume_if_exists);
  return request;
}

}  // namespace vantage
