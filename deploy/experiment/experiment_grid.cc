#include "deploy/experiment/experiment_grid.h"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <fstream>
#include <map>
#include <set>
#include <sstream>

#include "absl/strings/str_cat.h"
#include "absl/strings/str_format.h"
#include "absl/strings/str_join.h"
#include "google/protobuf/util/json_util.h"

namespace vantage {
namespace {

// One setting of a cell and where in the file it came from.
struct Setting {
  std::string flag;
  std::string value;
  std::string origin;
  // Set together with the env in one point (the env's own batch size or
  // ensemble): part of the env, not of the group's name.
  bool env_bound = false;
};
using Point = std::vector<Setting>;

// Flags a cell's settings may not name: the experiment sets them itself
// (seeds, the run directory) or they would run something else than a
// training cell.
const std::set<std::string>& ReservedFlags() {
  static const auto* reserved = new std::set<std::string>{
      "seed", "config", "run_dir", "resume", "resume_if_exists"};
  return *reserved;
}

// Flags the group name spells out itself or that make the path around it.
bool NamedByGroupOrPath(const std::string& flag) {
  static const auto* named =
      new std::set<std::string>{"env", "seed", "estimator", "rho", "ensemble"};
  return named->count(flag) > 0;
}

// More cells than any machine or cluster would run: a file that expands
// beyond it is refused before the grid is built.
constexpr size_t kMaxCells = 100000;

absl::Status Invalid(const std::string& file, const std::string& field,
                     const std::string& message) {
  return absl::InvalidArgumentError(
      absl::StrCat(file, ": ", field, ": ", message));
}

// Letters, digits, '.', '_' and '-' stay; ':' goes (order:2 -> order2);
// anything else becomes '_'.
std::string PathSafe(const std::string& text) {
  std::string safe;
  for (char c : text) {
    if (std::isalnum(static_cast<unsigned char>(c)) || c == '.' || c == '_' ||
        c == '-') {
      safe.push_back(c);
    } else if (c == ',') {
      safe.push_back('-');
    } else if (c != ':') {
      safe.push_back('_');
    }
  }
  // Never a name that walks out of the experiment directory.
  if (safe.empty() || safe == "." || safe == "..") safe = "_" + safe;
  return safe;
}

class Expander {
 public:
  Expander(const pb::Experiment& experiment, const ExpandOptions& options,
           const RunSettingsSchema& schema)
      : experiment_(experiment),
        options_(options),
        schema_(schema),
        known_(schema.flags.begin(), schema.flags.end()) {}

  absl::StatusOr<pb::ExpandedExperiment> Expand() {
    if (!(options_.budget > 0) || !std::isfinite(options_.budget)) {
      return absl::InvalidArgumentError(absl::StrCat(
          "--budget must be a number > 0 (the share of each cell's steps), "
          "not ",
          options_.budget));
    }
    absl::StatusOr<Seeds> seeds = ChooseSeeds();
    if (!seeds.ok()) return seeds.status();
    absl::StatusOr<std::vector<Point>> points = AllPoints();
    if (!points.ok()) return points.status();
    if (absl::Status status = CheckReport(); !status.ok()) return status;
    if (points->size() * seeds->values.size() > kMaxCells) {
      return absl::InvalidArgumentError(absl::StrCat(
          options_.file, ": ", points->size() * seeds->values.size(),
          " cells, more than ", kMaxCells));
    }

    pb::ExpandedExperiment expanded;
    expanded.set_name(experiment_.name());
    expanded.set_description(experiment_.description());
    expanded.set_file(options_.file);
    expanded.set_budget(options_.budget);
    *expanded.mutable_report() = experiment_.report();
    if (expanded.report().baseline().empty()) {
      expanded.mutable_report()->set_baseline("gae");
    }
    if (absl::Status status = AddCells(*points, *seeds, expanded);
        !status.ok()) {
      return status;
    }
    if (absl::Status status = CheckThresholdEnvs(expanded); !status.ok()) {
      return status;
    }
    return expanded;
  }

 private:
  struct Seeds {
    std::vector<uint64_t> values;
    std::string origin;  // --seeds or the file's seeds
  };

  absl::StatusOr<Seeds> ChooseSeeds() const {
    Seeds seeds{options_.seeds, "--seeds"};
    if (seeds.values.empty()) {
      seeds.values.assign(experiment_.seeds().begin(),
                          experiment_.seeds().end());
      seeds.origin = "seeds";
    }
    if (seeds.values.empty()) {
      return Invalid(options_.file, "seeds", "list at least one seed");
    }
    if (std::set<uint64_t>(seeds.values.begin(), seeds.values.end()).size() !=
        seeds.values.size()) {
      return Invalid(options_.file, seeds.origin, "a seed is listed twice");
    }
    return seeds;
  }

  // The axes' product, or each variant's on top of it.
  absl::StatusOr<std::vector<Point>> AllPoints() {
    absl::StatusOr<std::vector<Point>> common =
        AxesProduct(experiment_.axes(), "axes", {Point()});
    if (!common.ok()) return common.status();
    if (experiment_.variants().empty()) return common;
    std::vector<Point> points;
    for (int v = 0; v < experiment_.variants_size(); ++v) {
      absl::StatusOr<std::vector<Point>> product = VariantPoints(v, *common);
      if (!product.ok()) return product.status();
      points.insert(points.end(), product->begin(), product->end());
    }
    return points;
  }

  absl::StatusOr<std::vector<Point>> VariantPoints(
      int v, const std::vector<Point>& common) {
    const pb::Variant& variant = experiment_.variants(v);
    const std::string field = absl::StrCat("variants[", v, "]");
    Point fixed;
    // A map's order is unspecified; sorted names keep cells stable.
    std::map<std::string, std::string> set(variant.set().begin(),
                                           variant.set().end());
    for (const auto& [flag, value] : set) {
      const std::string origin = absl::StrCat(field, ".set.", flag);
      if (absl::Status status = CheckFlag(flag, origin); !status.ok()) {
        return status;
      }
      fixed.push_back({flag, value, origin});
    }
    std::vector<Point> starts;
    for (const Point& point : common) starts.push_back(Join(point, fixed));
    return AxesProduct(variant.axes(), absl::StrCat(field, ".axes"), starts);
  }

  // Each point once per seed, in that order; no two cells may share a run
  // directory.
  absl::Status AddCells(const std::vector<Point>& points, const Seeds& seeds,
                        pb::ExpandedExperiment& expanded) {
    std::map<std::string, std::string> origin_of_dir;
    for (const Point& point : points) {
      if (absl::Status status = CheckRepeats(point); !status.ok()) {
        return status;
      }
      for (uint64_t seed : seeds.values) {
        absl::StatusOr<pb::ExperimentCell> cell =
            MakeCell(point, seed, seeds.origin);
        if (!cell.ok()) return cell.status();
        const std::string origins = OriginsText(point);
        auto [it, inserted] = origin_of_dir.emplace(cell->dir(), origins);
        if (!inserted) {
          return absl::InvalidArgumentError(absl::StrCat(
              options_.file, ": two cells are both ", cell->dir(), " (from ",
              it->second, " and from ", origins, ")",
              cell->config().advantage().estimator() == "gae"
                  ? "; the gae estimator ignores rho and ensemble, so give "
                    "it a variant of its own"
                  : "; settings set together with the env in one point do "
                    "not name groups"));
        }
        *expanded.add_cells() = *std::move(cell);
      }
    }
    return absl::OkStatus();
  }

  absl::Status CheckThresholdEnvs(const pb::ExpandedExperiment& expanded) {
    std::set<std::string> envs;
    for (const pb::ExperimentCell& cell : expanded.cells()) {
      envs.insert(cell.env());
    }
    for (const auto& [env, threshold] : experiment_.report().thresholds()) {
      if (envs.count(env) == 0) {
        return Invalid(
            options_.file, absl::StrCat("report.thresholds.", env),
            absl::StrCat("no cell of this experiment runs ", env,
                         " (its envs: ", absl::StrJoin(envs, ", "), ")"));
      }
    }
    return absl::OkStatus();
  }

  static Point Join(const Point& a, const Point& b) {
    Point joined = a;
    joined.insert(joined.end(), b.begin(), b.end());
    return joined;
  }

  absl::Status CheckFlag(const std::string& flag, const std::string& origin) {
    if (ReservedFlags().count(flag) > 0) {
      return Invalid(
          options_.file, origin,
          flag == "seed"
              ? "seeds are the experiment's `seeds` (or --seeds), not a "
                "setting"
              : absl::StrCat("--", flag, " is the runner's to set"));
    }
    if (known_.count(flag) == 0) {
      return Invalid(options_.file, origin,
                     absl::StrCat("'", flag, "' is not a run flag; they are: ",
                                  absl::StrJoin(schema_.flags, ", ")));
    }
    return absl::OkStatus();
  }

  // The axis' points: one setting per value, or each point's settings.
  absl::StatusOr<std::vector<Point>> AxisPoints(const pb::Axis& axis,
                                                const std::string& field) {
    const bool by_flag = !axis.flag().empty() || !axis.values().empty();
    if (by_flag == !axis.points().empty()) {
      return Invalid(options_.file, field,
                     "give either flag and values, or points");
    }
    std::vector<Point> points;
    if (by_flag) {
      if (axis.flag().empty()) {
        return Invalid(options_.file, absl::StrCat(field, ".flag"),
                       "name the flag its values set");
      }
      if (absl::Status status =
              CheckFlag(axis.flag(), absl::StrCat(field, ".flag"));
          !status.ok()) {
        return status;
      }
      if (axis.values().empty()) {
        return Invalid(options_.file, absl::StrCat(field, ".values"),
                       "list at least one value");
      }
      for (int i = 0; i < axis.values_size(); ++i) {
        points.push_back({{axis.flag(), axis.values(i),
                           absl::StrCat(field, ".values[", i, "]")}});
      }
      return points;
    }
    for (int i = 0; i < axis.points_size(); ++i) {
      const std::string point_field = absl::StrCat(field, ".points[", i, "]");
      if (axis.points(i).flags().empty()) {
        return Invalid(options_.file, point_field,
                       "a point sets at least one flag");
      }
      std::map<std::string, std::string> flags(axis.points(i).flags().begin(),
                                               axis.points(i).flags().end());
      Point point;
      for (const auto& [flag, value] : flags) {
        const std::string origin = absl::StrCat(point_field, ".", flag);
        if (absl::Status status = CheckFlag(flag, origin); !status.ok()) {
          return status;
        }
        point.push_back({flag, value, origin, flags.count("env") > 0});
      }
      points.push_back(std::move(point));
    }
    return points;
  }

  absl::StatusOr<std::vector<Point>> AxesProduct(
      const google::protobuf::RepeatedPtrField<pb::Axis>& axes,
      const std::string& field, std::vector<Point> product) {
    for (int a = 0; a < axes.size(); ++a) {
      absl::StatusOr<std::vector<Point>> points =
          AxisPoints(axes[a], absl::StrCat(field, "[", a, "]"));
      if (!points.ok()) return points.status();
      if (product.size() * points->size() > kMaxCells) {
        return Invalid(
            options_.file, absl::StrCat(field, "[", a, "]"),
            absl::StrCat("the grid grows beyond ", kMaxCells, " cells"));
      }
      std::vector<Point> next;
      for (const Point& start : product) {
        for (const Point& point : *points) next.push_back(Join(start, point));
      }
      product = std::move(next);
    }
    return product;
  }

  absl::Status CheckRepeats(const Point& point) {
    std::map<std::string, std::string> seen;
    for (const Setting& setting : point) {
      auto [it, inserted] = seen.emplace(setting.flag, setting.origin);
      if (!inserted) {
        return absl::InvalidArgumentError(absl::StrCat(
            options_.file, ": ", it->second, " and ", setting.origin,
            " both set --", setting.flag, " in one cell"));
      }
    }
    return absl::OkStatus();
  }

  absl::Status CheckReport() {
    for (const auto& [env, threshold] : experiment_.report().thresholds()) {
      if (!std::isfinite(threshold)) {
        return Invalid(options_.file, absl::StrCat("report.thresholds.", env),
                       "must be a finite number");
      }
    }
    return absl::OkStatus();
  }

  static std::string OriginsText(const Point& point) {
    if (point.empty()) return "the base alone";
    std::vector<std::string> origins;
    for (const Setting& setting : point) origins.push_back(setting.origin);
    return absl::StrJoin(origins, ", ");
  }

  absl::StatusOr<pb::ExperimentCell> MakeCell(const Point& point, uint64_t seed,
                                              const std::string& seed_origin) {
    FlagSettings settings;
    std::map<std::string, std::string> origins;
    for (const Setting& setting : point) {
      settings.emplace_back(setting.flag, setting.value);
      origins[setting.flag] = setting.origin;
    }
    settings.emplace_back("seed", absl::StrCat(seed));
    origins["seed"] = seed_origin;
    auto fail = [&](const absl::Status& status) {
      return absl::InvalidArgumentError(
          absl::StrCat(options_.file, ": the cell of ", OriginsText(point),
                       ", seed ", seed, ": ", status.message()));
    };
    absl::StatusOr<pb::RunConfig> config =
        schema_.resolve(experiment_.base(), settings);
    if (!config.ok()) return fail(config.status());
    if (options_.budget != 1.0) {
      const double scaled =
          static_cast<double>(config->training().steps()) * options_.budget;
      if (scaled > 1e15) {
        return fail(absl::InvalidArgumentError(absl::StrCat(
            "--budget=", options_.budget, " makes ", scaled, " steps")));
      }
      const int64_t steps = std::max<int64_t>(1, std::llround(scaled));
      auto given =
          std::find_if(settings.begin(), settings.end(),
                       [](const auto& s) { return s.first == "steps"; });
      if (given != settings.end()) settings.erase(given);
      settings.emplace_back("steps", absl::StrCat(steps));
      origins["steps"] = "--budget";
      config = schema_.resolve(experiment_.base(), settings);
      if (!config.ok()) return fail(config.status());
    }
    FlagSettings extra;
    for (const Setting& setting : point) {
      if (!NamedByGroupOrPath(setting.flag) && !setting.env_bound) {
        extra.emplace_back(setting.flag, setting.value);
      }
    }
    pb::ExperimentCell cell;
    cell.set_env(config->training().env());
    cell.set_group(GroupName(*config, extra));
    cell.set_seed(seed);
    cell.set_dir(
        absl::StrCat(PathSafe(cell.env()), "/", cell.group(), "/seed-", seed));
    for (const auto& [flag, value] : settings)
      (*cell.mutable_flags())[flag] = value;
    for (const auto& [flag, origin] : origins) {
      (*cell.mutable_origins())[flag] = origin;
    }
    *cell.mutable_config() = *std::move(config);
    return cell;
  }

  const pb::Experiment& experiment_;
  const ExpandOptions& options_;
  const RunSettingsSchema& schema_;
  const std::set<std::string> known_;
};

}  // namespace

std::string GroupName(const pb::RunConfig& resolved,
                      const FlagSettings& extra) {
  const pb::AdvantageSettings& advantage = resolved.advantage();
  std::string name = PathSafe(advantage.estimator());
  if (advantage.estimator() != "gae") {
    absl::StrAppend(&name, absl::StrFormat("-rho%g", advantage.rho()), "-E",
                    absl::StrJoin(advantage.ensemble(), "-"));
  }
  for (const auto& [flag, value] : extra) {
    absl::StrAppend(&name, "-", PathSafe(flag), "_", PathSafe(value));
  }
  return name;
}

absl::StatusOr<pb::Experiment> ParseExperimentJson(const std::string& json,
                                                   const std::string& name) {
  pb::Experiment experiment;
  const auto status =
      google::protobuf::util::JsonStringToMessage(json, &experiment);
  if (!status.ok()) {
    return absl::InvalidArgumentError(
        absl::StrCat(name, ": ", status.message().as_string()));
  }
  return experiment;
}

absl::StatusOr<pb::Experiment> ReadExperimentFile(const std::string& path) {
  std::ifstream file(path);
  if (!file) {
    return absl::NotFoundError(
        absl::StrCat("cannot read experiment file ", path));
  }
  std::stringstream text;
  text << file.rdbuf();
  return ParseExperimentJson(text.str(), path);
}

absl::StatusOr<pb::ExpandedExperiment> ExpandExperiment(
    const pb::Experiment& experiment, const ExpandOptions& options,
    const RunSettingsSchema& schema) {
  return Expander(experiment, options, schema).Expand();
}

}  // namespace vantage
