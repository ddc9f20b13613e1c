// Parameter tables for Python (params.h): one reader of keywords and one writer of rows for every
// table, the built-in ones (bindings.cpp binds their structs) and a sequence method's (a plugin's).
#include "params.h"

#include <nanobind/stl/string.h>
#include <nanobind/stl/vector.h>

#include <vector>

#include "atrous/error.h"

namespace atrous::python {

namespace {

template <class T>
T as(const nb::handle& v, const std::string& key) {
    try {
        return nb::cast<T>(v);
    } catch (const std::exception&) {
        throw InputError("parameter '" + key + "' has the wrong type");
    }
}

nb::object paramValue(const ParamSet& set, size_t i) {
    const ParamRef r = set.at(i);
    if (int* const* n = std::get_if<int*>(&r)) return nb::cast(**n);
    if (uint32_t* const* u = std::get_if<uint32_t*>(&r)) return nb::cast(**u);
    if (float* const* x = std::get_if<float*>(&r)) return nb::cast(double(**x));
    if (bool* const* b = std::get_if<bool*>(&r)) return nb::cast(**b);
    if (std::get_if<SureMode*>(&r)) return nb::cast(paramText(r, set.rows()[i].choices));
    return nb::cast(*std::get<std::vector<float>*>(r));
}

}  // namespace

void applyParam(ParamSet& set, const std::string& k, const nb::handle& v, const char* what) {
    int row = set.find(k);
    bool negate = false;
    for (size_t i = 0; row < 0 && i < set.rows().size(); ++i)
        if (set.rows()[i].negated && k == negatedKeyword(set.rows()[i])) row = int(i), negate = true;
    if (row < 0) throw InputError("unknown " + std::string(what) + " parameter '" + k + "'" + didYouMean(k, paramKeywords(set)));
    const ParamRow& f = set.rows()[size_t(row)];
    const ParamRef r = set.at(size_t(row));
    if (int* const* n = std::get_if<int*>(&r)) **n = as<int>(v, k);
    else if (uint32_t* const* u = std::get_if<uint32_t*>(&r)) {
        const long long x = as<long long>(v, k);  // range-checked here: a cast would wrap
        if (x < 0 || x > 4294967295LL) throw ParamError(set.set(), f.name, f.range.rule(false), std::to_string(x));
        **u = uint32_t(x);
    } else if (float* const* x = std::get_if<float*>(&r)) **x = as<float>(v, k);
    else if (bool* const* b = std::get_if<bool*>(&r)) **b = as<bool>(v, k) != negate;
    else if (std::get_if<SureMode*>(&r)) set.setText(size_t(row), as<std::string>(v, k));
    else *std::get<std::vector<float>*>(r) = as<std::vector<float>>(v, k);
}

void applyParams(ParamSet& set, const nb::dict& params, const char* what) {
    for (auto [k, v] : params) applyParam(set, nb::cast<std::string>(k), v, what);
}

nb::list paramRows(const ParamSet& set) {
    static const char* const kKinds[] = {"int", "float", "bool", "choice", "float_list", "uint"};
    nb::list rows;
    for (size_t i = 0; i < set.rows().size(); ++i) {
        const ParamRow& f = set.rows()[i];
        nb::dict d;
        d["name"] = f.name;
        d["kind"] = kKinds[int(f.kind)];
        d["default"] = paramValue(set, i);
        const bool numeric = f.kind != ParamKind::Bool && f.kind != ParamKind::Choice;
        d["min"] = numeric ? nb::cast(f.range.lo) : nb::none();
        d["max"] = numeric ? nb::cast(f.range.hi) : nb::none();
        d["min_open"] = numeric && f.range.loOpen;  // (min, max]
        d["zero"] = f.range.zero && numeric ? nb::cast(std::string(f.range.zero)) : nb::none();
        const bool isFloat = f.kind == ParamKind::Float || f.kind == ParamKind::FloatList;
        d["rule"] = numeric ? nb::cast(f.range.rule(isFloat)) : nb::none();
        nb::list choices;
        for (int c = 0; f.choices && f.choices[c]; ++c) choices.append(f.choices[c]);
        d["choices"] = choices;
        d["doc"] = f.doc;
        d["group"] = f.group;
        d["flag"] = f.flag;
        d["aliases"] = f.negated ? nb::cast(std::vector<std::string>{negatedKeyword(f)}) : nb::cast(std::vector<std::string>{});
        rows.append(d);
    }
    return rows;
}

nb::dict paramValues(const ParamSet& set) {
    nb::dict d;
    for (size_t i = 0; i < set.rows().size(); ++i) d[set.rows()[i].name] = paramValue(set, i);
    return d;
}

}  // namespace atrous::python
