// The settings schema: every user-facing numeric setting of an option struct is described once —
// the library field it sets, its name at the interfaces (unit included), its unit and factor to
// SI, its default (the option struct's own initial value) and its range — and the study reader,
// the command line and the Python module read, default, check and name it from that
// description. No front end writes a default or a range check of its own.
//
// Spellings. The setting {section "noise", field "sigma", name "sigma_mm"} is
//   noise.sigma       in the library (NoiseModel::sigma, metres) and in library errors,
//   noise.sigma_mm    in a study file,
//   --sigma-mm        on the command line,
//   sigma_mm=         in Python.
// A library check throws SettingError, which names the library field and the value in SI; each
// front end respells it (SettingError::Respelled) so that its users read their own names and
// units.
#pragma once

#include <limits>
#include <string>
#include <vector>

#include "lrcal/core/error.h"

namespace lrcal {

/// +∞: the open upper end of a setting's range (SettingSpec::max), one definition for every
/// settings table.
inline constexpr double kInf = std::numeric_limits<double>::infinity();

/// Who reads a setting, for its spelling in messages.
enum class Frontend { kLibrary, kStudyFile, kCommandLine, kPython };

/// One numeric setting.
struct SettingSpec {
  const char* section;       ///< the option struct's section: "noise", "run"
  const char* field;         ///< its member, in SI: "sigma"
  const char* name;          ///< the name at the interfaces, its unit included: "sigma_mm"
  const char* unit;          ///< the unit of values at the interfaces: "mm", "mrad", "" (none)
  double to_si = 1;          ///< a value in `unit` × to_si = the member's SI value
  const char* si_unit = "";  ///< the member's unit: "m", "rad", "" (none)
  double min = 0;            ///< smallest allowed value, in `unit`
  double max = std::numeric_limits<double>::infinity();  ///< largest allowed value, in `unit`
  bool min_exclusive = false;  ///< min itself is not allowed (a scale > 0)
  bool integer = false;        ///< a whole number
  const char* noun = "";       ///< what a value counts, for whole numbers: "readings per ..."
  const char* min_note = "";   ///< what the smallest value means, if special: "all cores"
  const char* help = "";       ///< one line for --help, docstrings and docs
  /// Python's name where it differs from `name` (a keyword that names a value, not an option:
  /// out_dir= for --out); null: `name`.
  const char* python_name = nullptr;
  bool max_exclusive = false;  ///< max itself is not allowed (a relative tolerance < 1)

  /// The setting as `frontend` spells it (see the file comment).
  std::string Spelling(Frontend frontend) const;
  /// What a valid value is, in `unit` (or in SI): "expected a finite value >= 0 (mm)",
  /// "expected 1 to 1,000,000 readings per configuration", "expected a value in [0, 1]".
  std::string Expected(bool si = false) const;
  /// True if `value_si` (SI) is allowed.
  bool Allows(double value_si) const;
  /// Throws SettingError unless Allows(value_si).
  void Check(double value_si) const;
  /// An SI value in `unit`, rounded to 12 significant digits (so 0.2e-3 m reads 0.2 mm).
  double FromSi(double value_si) const;
  /// A setting that is not a number (a folder, a name, a choice), for SettingError's spelling
  /// only: {section, field, name}, no unit and no range.
  static SettingSpec Named(const char* section, const char* field, const char* name,
                           const char* help = "", const char* python_name = nullptr);
};

/// A setting out of its range. what() names the library field and the SI value; front ends
/// show Respelled(their frontend) instead.
class SettingError : public InputError {
 public:
  /// A value out of the spec's range.
  SettingError(const SettingSpec& spec, double value_si);
  /// Any other problem with the setting (`problem` says what was expected, in the setting's
  /// terms, with no unit conversion needed).
  SettingError(const SettingSpec& spec, const std::string& problem);
  /// A problem whose text names other settings as {0}, {1}, ...: `mentions`[i], each spelt as
  /// the front end spells it ("--plan-on", "plan_on=", "plan.plan_on"), so that advice such as
  /// "or plan on the reading noise's part alone ({0} data)" is in the reader's words.
  SettingError(const SettingSpec& spec, const std::string& problem,
               std::vector<SettingSpec> mentions);
  const SettingSpec& spec() const { return spec_; }
  /// "expected a finite value >= 0 (mm), got -1": the value in the setting's unit (other
  /// settings named as the library names them).
  std::string Problem() const { return ProblemFor(Frontend::kLibrary); }
  /// The error as `frontend` says it: "--sigma-mm: expected ..., got -1". A study file's
  /// reader passes the location of the key as `where` ("s.yaml:4 key 'noise.sigma_mm'").
  InputError Respelled(Frontend frontend, const std::string& where = "") const;

 private:
  std::string ProblemFor(Frontend frontend) const;
  SettingSpec spec_;
  std::string problem_;
  std::vector<SettingSpec> mentions_;
};

/// A setting bound to a member of the option struct `Options` (a double, an int or a long long,
/// in SI).
template <class Options>
struct SettingField {
  SettingSpec spec;
  double Options::*real = nullptr;
  int Options::*whole = nullptr;
  long long Options::*count = nullptr;
  /// The member's value (SI); NaN if the field is bound to no member.
  double Get(const Options& o) const {
    if (real) return o.*real;
    if (whole) return static_cast<double>(o.*whole);
    if (count) return static_cast<double>(o.*count);
    return std::numeric_limits<double>::quiet_NaN();
  }
  void Set(Options* o, double value_si) const {
    if (real) o->*real = value_si;
    if (whole) o->*whole = static_cast<int>(value_si);
    if (count) o->*count = static_cast<long long>(value_si);
  }
  /// The default: the member's initial value in a default-constructed Options, in `unit`.
  double Default() const {
    static const Options defaults{};
    return spec.FromSi(Get(defaults));
  }
};

/// Checks every field of `options` against its spec (throws SettingError for the first bad one).
template <class Options>
void CheckSettings(const Options& options, const std::vector<SettingField<Options>>& fields) {
  for (const SettingField<Options>& f : fields) f.spec.Check(f.Get(options));
}

/// Finds the field whose spec has `name` (the interface name, "sigma_mm"); null if none.
template <class Options>
const SettingField<Options>* FindSetting(const std::vector<SettingField<Options>>& fields,
                                         const std::string& name) {
  for (const SettingField<Options>& f : fields)
    if (name == f.spec.name) return &f;
  return nullptr;
}

}  // namespace lrcal
