// Parameter tables for Python (include/atrous/param_set.h): a table's rows as dicts
// (atrous.denoise_params(), a sequence method's params) and keywords applied to a set, whatever
// the struct behind it, for every binding file.
#pragma once
#include <nanobind/nanobind.h>

#include <string>

#include "atrous/param_set.h"

namespace atrous::python {

namespace nb = nanobind;

// A keyword of the set's table: its row's name, or for a negated switch the CLI's negative name
// too (no_firefly=True is firefly=False). The value is converted to the field's kind; InputError
// "unknown <what> parameter 'k'" for a keyword of no row.
void applyParam(ParamSet& set, const std::string& key, const nb::handle& value, const char* what);
void applyParams(ParamSet& set, const nb::dict& params, const char* what);
// The rows as dicts (name, kind, default: the set's value, min, max, ..., flag, aliases).
nb::list paramRows(const ParamSet& set);
// {name: value} for every row (a choice as its name).
nb::dict paramValues(const ParamSet& set);

}  // namespace atrous::python
