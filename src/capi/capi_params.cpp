// A C API filter's parameters, by the names of denoiseParams()'s table (atrous/params.h), and what
// its last execution reported (atrousGetFilter*).
#include <string>

#include "atrous/error.h"
#include "atrous/params.h"
#include "capi/capi_impl.h"

using namespace atrous;
using atrous::capi::Failure;

namespace {

using Field = ParamField<DenoiseOptions>;

[[noreturn]] void invalid(const std::string& message) {
    throw Failure{ATROUS_ERROR_INVALID_ARGUMENT, message};
}

const Field& fieldOf(const char* name, const char* reportNames = nullptr) {
    if (!name) invalid("name is NULL");
    if (const Field* f = denoiseParams().find(name)) return *f;
    std::string names;
    for (const Field& f : denoiseParams()) names += std::string(names.empty() ? "" : ", ") + f.name;
    invalid(std::string("no parameter '") + name + "' (the parameters are " + names +
            (reportNames ? std::string("; ") + reportNames : std::string()) + ")");
}

constexpr const char* kIntReport = "and of the last run nonfinite_pixels, fireflies_clamped";
constexpr const char* kFloatReport = "and of the last run milliseconds";
constexpr const char* kBoolReport = "and of the last run noise_estimated";
constexpr const char* kStringReport = "and of the last run method, buffers";

// A parameter of another kind than the call's: which call takes it. `call` is "atrousSetFilter" or
// "atrousGetFilter".
[[noreturn]] void wrongKind(const Field& f, const char* call) {
    static const char* const kinds[] = {"an integer", "a float", "a boolean",
                                        "a choice",   "a list",  "an integer"};
    static const char* const calls[] = {"Int", "Float", "Bool", "String", "String", "Int"};
    const int k = int(f.kind());
    invalid(std::string("parameter ") + f.name + " is " + kinds[k] + ": use " + call + calls[k]);
}

// The field's value when it is a T, else wrongKind.
template <class T>
T& fieldAs(const Field& f, const ParamRef& r, const char* call) {
    if (T* const* p = std::get_if<T*>(&r)) return **p;
    wrongKind(f, call);
}

// Sets parameter `name` on a copy of the options (set(field, its ref in the copy, the copy)) and
// keeps the copy when the table's checks pass: a value out of range is a ParamError naming the
// field, and nothing is set.
template <class Set>
void setChecked(DenoiseOptions& options, const char* name, Set set) {
    const Field& f = fieldOf(name);
    DenoiseOptions o = options;
    set(f, f.at(o), o);
    validateParams(o, denoiseParams());
    options = o;
}

const char* nameOrNull(const char* s) {
    return s ? s : "(null)";
}

void needRun(bool ran, const char* name) {
    if (!ran)
        throw Failure{ATROUS_ERROR_INVALID_OPERATION,
                      std::string("'") + name + "' is known after atrousExecuteFilter"};
}

}  // namespace

void AtrousFilterImpl::setInt(const char* name, int value) {
    committed = false;
    setChecked(options, name, [&](const Field& f, const ParamRef& r, DenoiseOptions&) {
        if (float* const* x = std::get_if<float*>(&r)) {
            **x = float(value);
        } else if (bool* const* b = std::get_if<bool*>(&r)) {
            if (value != 0 && value != 1)
                invalid(std::string("parameter ") + f.name + " is a boolean: 0 or 1 (got " +
                        std::to_string(value) + ")");
            **b = value != 0;
        } else {
            fieldAs<int>(f, r, "atrousSetFilter") = value;
        }
    });
}

void AtrousFilterImpl::setFloat(const char* name, float value) {
    committed = false;
    setChecked(options, name, [&](const Field& f, const ParamRef& r, DenoiseOptions&) {
        fieldAs<float>(f, r, "atrousSetFilter") = value;
    });
}

void AtrousFilterImpl::setBool(const char* name, bool value) {
    committed = false;
    setChecked(options, name, [&](const Field& f, const ParamRef& r, DenoiseOptions&) {
        fieldAs<bool>(f, r, "atrousSetFilter") = value;
    });
}

void AtrousFilterImpl::setString(const char* name, const char* value) {
    committed = false;
    setChecked(options, name, [&](const Field& f, const ParamRef&, DenoiseOptions& o) {
        if (f.kind() != ParamKind::Choice && f.kind() != ParamKind::FloatList)
            wrongKind(f, "atrousSetFilter");
        if (!value) invalid("value is NULL");
        setParamFromText(o, denoiseParams(), f, value);
    });
}

int AtrousFilterImpl::getInt(const char* name) {
    const std::string n = nameOrNull(name);
    if (n == "nonfinite_pixels" || n == "fireflies_clamped") {
        needRun(ran, name);
        return n == "nonfinite_pixels" ? report.nonFinitePixels : report.firefliesClamped;
    }
    const Field& f = fieldOf(name, kIntReport);
    const ParamRef r = f.at(options);
    if (int* const* i = std::get_if<int*>(&r)) return **i;
    if (bool* const* b = std::get_if<bool*>(&r)) return **b ? 1 : 0;
    if (SureMode* const* m = std::get_if<SureMode*>(&r)) return int(**m);
    wrongKind(f, "atrousGetFilter");
}

float AtrousFilterImpl::getFloat(const char* name) {
    if (std::string(nameOrNull(name)) == "milliseconds") {
        needRun(ran, name);
        return float(report.milliseconds);
    }
    const Field& f = fieldOf(name, kFloatReport);
    const ParamRef r = f.at(options);
    if (float* const* x = std::get_if<float*>(&r)) return **x;
    if (int* const* i = std::get_if<int*>(&r)) return float(**i);
    wrongKind(f, "atrousGetFilter");
}

bool AtrousFilterImpl::getBool(const char* name) {
    if (std::string(nameOrNull(name)) == "noise_estimated") {
        needRun(ran, name);
        return report.noiseEstimated;
    }
    const Field& f = fieldOf(name, kBoolReport);
    return fieldAs<bool>(f, f.at(options), "atrousGetFilter");
}

const char* AtrousFilterImpl::getString(const char* name) {
    const std::string n = nameOrNull(name);
    if (n == "method") {
        text = denoiseMethodName(ran ? report.methodUsed : options.method);
    } else if (n == "buffers") {
        needRun(ran, name);
        text = report.buffersUsed;
    } else {
        const Field& f = fieldOf(name, kStringReport);
        text = paramText(f.at(options), f.choices);
    }
    return text.c_str();
}
