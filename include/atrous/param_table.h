// The machinery of the parameter tables: one table per parameter set lists each field once with
// the name users know it by (snake_case: the Python keyword, the CLI flag with '-' for '_', the name
// in error messages), a doc line, its range and where it lives in the struct. Validation, the CLI's
// flags, Python's keywords, the viewer's controls and equality all walk a table, so a new field is
// one new line in its table (tests/params_test.cpp checks that every struct field has one).
// Defaults are never copied: they are what a default-constructed struct holds. The tables
// themselves live with their structs' layers: the filters' in atrous/params.h, the renderer's
// (renderParams()) in atrous/render.h.
#pragma once
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <iterator>
#include <limits>
#include <string>
#include <variant>
#include <vector>

#include "atrous/error.h"

namespace atrous {

// The one Choice field's enum (SURE's mode, atrous/denoise.h), named here so that a field of that
// kind has its alternative in ParamRef; its names are the row's `choices`.
enum class SureMode;

// Where a field lives; its alternative is the field's kind.
using ParamRef = std::variant<int*, float*, bool*, SureMode*, std::vector<float>*, uint32_t*>;
enum class ParamKind { Int, Float, Bool, Choice, FloatList, UInt };  // ParamRef's alternatives, in order

// The values a number may take (a FloatList's elements, for a list): finite, in [lo, hi] or
// (lo, hi]; `zero` also allows 0 and says what it means ("off", "automatic").
struct ParamRange {
    double lo = -std::numeric_limits<double>::infinity();
    double hi = std::numeric_limits<double>::infinity();
    bool loOpen = false;
    const char* zero = nullptr;

    // Floats compare in float, as the filters see them (1e-6f is below the double 1e-6).
    bool allows(double v, bool isFloat) const {
        if (!std::isfinite(v)) return false;
        if (zero && v == 0) return true;
        const double l = isFloat ? double(float(lo)) : lo, h = isFloat ? double(float(hi)) : hi;
        return (loOpen ? v > l : v >= l) && v <= h;
    }
    std::string rule(bool isFloat) const;
};

constexpr ParamRange paramIn(double lo, double hi) { return {lo, hi, false, nullptr}; }    // [lo, hi], lo..hi
constexpr ParamRange paramAbove(double lo, double hi) { return {lo, hi, true, nullptr}; }  // (lo, hi]
constexpr ParamRange paramAtLeast(double lo) { return {lo, std::numeric_limits<double>::infinity(), false, nullptr}; }
constexpr ParamRange paramZeroOr(double lo, const char* zero) {
    return {lo, std::numeric_limits<double>::infinity(), false, zero};
}

template <class S>
struct ParamField {
    const char* name;    // snake_case, unique in its table
    ParamRef (*at)(S&);  // the field in a struct
    ParamRange range;    // Int, Float and FloatList elements; unused for Bool and Choice
    const char* doc;     // one line: the CLI's help, Python's and the viewer's tooltip
    const char* group = "";  // denoiseParams(): the still stage that reads it ("eaw", "sure", "firefly", "emission", "safety", "" the preparation); others: ""
    const char* flag = nullptr;     // the CLI flag without "--" when it is not the table's rule; "" = none
    bool negated = false;           // Bool: the CLI flag (--no-<name>) clears it; Python accepts no_<name> too
    const char* const* choices = nullptr;      // Choice: the names of the enum's values, in order, null-ended
    std::string (*check)(const S&) = nullptr;  // a rule that involves other fields: "" or what is wrong
    ParamKind kind() const {
        static S probe{};
        return ParamKind(at(probe).index());
    }
};

template <class S>
struct ParamTable {
    const char* set;         // "denoise" | "svgf" | "render" (ParamError::set)
    const char* flagPrefix;  // CLI flag = "--" + flagPrefix + name with '-' for '_'
    const ParamField<S>* first;
    size_t count;
    const ParamField<S>* begin() const { return first; }
    const ParamField<S>* end() const { return first + count; }
    const ParamField<S>* find(const std::string& name) const {
        for (const auto& f : *this)
            if (name == f.name) return &f;
        return nullptr;
    }
    std::string flag(const ParamField<S>& f) const;  // "--sigma-normal", "--no-firefly", "--svgf-alpha"; "" = none
};

namespace params_detail {
template <class T>
struct ClassOf;
template <class S, class V>
struct ClassOf<V S::*> {
    using type = S;
};
template <auto M>
ParamRef at(typename ClassOf<decltype(M)>::type& s) {
    return &(s.*M);
}
template <auto Outer, auto Inner>
ParamRef at2(typename ClassOf<decltype(Outer)>::type& s) {
    return &(s.*Outer.*Inner);
}
}  // namespace params_detail

// ---- what the consumers share -------------------------------------------------------------------

// The name of `names` closest to `got` (an unknown parameter, flag or keyword) by edit distance
// (insertions, deletions, substitutions and swaps of neighbours, each 1; case, '-' and '_' ignored),
// when it is near enough to be a slip: at most 2 edits, and fewer than half of `got`'s length. ""
// when none is. For "did you mean ...?" after an unknown name (Python's keywords, the CLI's flags).
inline std::string closestName(const std::string& got, const std::vector<std::string>& names) {
    auto norm = [](std::string s) {
        for (char& c : s) c = c == '-' ? '_' : char(c >= 'A' && c <= 'Z' ? c - 'A' + 'a' : c);
        return s;
    };
    const std::string a = norm(got);
    std::string best;
    size_t bestD = std::min<size_t>(3, (a.size() + 1) / 2);  // a candidate must beat this
    for (const std::string& name : names) {
        const std::string b = norm(name);
        // Optimal string alignment distance, three rows.
        std::vector<size_t> p2(b.size() + 1), p1(b.size() + 1), cur(b.size() + 1);
        for (size_t j = 0; j <= b.size(); ++j) p1[j] = j;
        for (size_t i = 1; i <= a.size(); ++i) {
            cur[0] = i;
            for (size_t j = 1; j <= b.size(); ++j) {
                cur[j] = std::min({p1[j] + 1, cur[j - 1] + 1, p1[j - 1] + (a[i - 1] == b[j - 1] ? 0 : 1)});
                if (i > 1 && j > 1 && a[i - 1] == b[j - 2] && a[i - 2] == b[j - 1]) cur[j] = std::min(cur[j], p2[j - 2] + 1);
            }
            p2.swap(p1);
            p1.swap(cur);
        }
        if (p1[b.size()] < bestD) bestD = p1[b.size()], best = name;
    }
    return best;
}

// " (did you mean 'NAME'?)" for closestName's answer, with `quote` around it; "" when there is none.
inline std::string didYouMean(const std::string& got, const std::vector<std::string>& names, const char* quote = "'") {
    const std::string n = closestName(got, names);
    return n.empty() ? "" : std::string(" (did you mean ") + quote + n + quote + "?)";
}

// The shortest text that reads back as the same float: 1e-6, 0.9, 1048576.
inline std::string formatParamNumber(double v) {
    if (!std::isfinite(v)) return std::isnan(v) ? "nan" : (v > 0 ? "inf" : "-inf");
    char buf[40];
    if (v == std::floor(v) && std::fabs(v) < 1e5) {
        std::snprintf(buf, sizeof buf, "%.0f", v);
        return buf;
    }
    for (int prec = 1; prec <= 9; ++prec) {
        std::snprintf(buf, sizeof buf, "%.*g", prec, v);
        if (float(std::strtod(buf, nullptr)) == float(v)) break;
    }
    std::string s = buf;
    const size_t e = s.find('e');
    if (e == std::string::npos) return s;
    std::string exp = s.substr(e + 1);
    const bool neg = exp[0] == '-';
    exp.erase(0, exp.find_first_not_of("+-0"));
    return s.substr(0, e) + "e" + (neg ? "-" : "") + exp;
}

inline std::string ParamRange::rule(bool isFloat) const {
    const bool open = std::isinf(hi);
    // Integer bounds in full (4294967295, not 4.2949673e9).
    auto text = [&](double v) { return isFloat || std::isinf(v) ? formatParamNumber(v) : std::to_string((long long)v); };
    const std::string l = text(lo), h = text(hi);
    if (zero) return std::string("must be 0 (") + zero + ") or " + (open ? ">= " + l : "in [" + l + ", " + h + "]");
    if (!isFloat) return open ? "must be at least " + l : "must be in " + l + ".." + h;
    if (open) return "must be a finite number " + std::string(loOpen ? "> " : ">= ") + l;
    return "must be in " + std::string(loOpen ? "(" : "[") + l + ", " + h + "]";
}

template <class S>
std::string ParamTable<S>::flag(const ParamField<S>& f) const {
    if (f.flag) return *f.flag ? std::string("--") + f.flag : std::string();
    std::string s = std::string("--") + flagPrefix + (f.negated ? "no-" : "") + f.name;
    for (char& c : s)
        if (c == '_') c = '-';
    return s;
}

// The field's value as text (the CLI's shown default, Python's repr of a choice).
inline std::string paramText(const ParamRef& r, const char* const* choices = nullptr) {
    struct V {
        const char* const* choices;
        std::string operator()(int* p) const { return std::to_string(*p); }
        std::string operator()(uint32_t* p) const { return std::to_string(*p); }
        std::string operator()(float* p) const { return formatParamNumber(*p); }
        std::string operator()(bool* p) const { return *p ? "true" : "false"; }
        std::string operator()(SureMode* p) const { return choices ? choices[int(*p)] : std::to_string(int(*p)); }
        std::string operator()(std::vector<float>* p) const {
            std::string s;
            for (float x : *p) s += (s.empty() ? "" : ",") + formatParamNumber(x);
            return s;
        }
    };
    return std::visit(V{choices}, r);
}

// Sets a Choice from its name ('_' accepted for '-') or a FloatList from "0,0.5,1"; other kinds
// are set by their own readers (CLI11, Python). ParamError naming the field otherwise.
template <class S>
void setParamFromText(S& s, const ParamTable<S>& t, const ParamField<S>& f, const std::string& text) {
    const ParamRef r = f.at(s);
    if (SureMode* const* m = std::get_if<SureMode*>(&r)) {
        std::string want, norm = text;
        for (char& c : norm)
            if (c == '_') c = '-';
        std::vector<std::string> names;
        for (int i = 0; f.choices[i]; ++i) {
            if (norm == f.choices[i]) {
                **m = SureMode(i);
                return;
            }
            want += std::string(i ? (f.choices[i + 1] ? ", " : " or ") : "") + f.choices[i];
            names.push_back(f.choices[i]);
        }
        throw ParamError(t.set, f.name, "must be " + want, "'" + text + "'" + didYouMean(text, names));
    }
    if (std::vector<float>* const* list = std::get_if<std::vector<float>*>(&r)) {
        std::vector<float> v;
        size_t start = 0;
        while (start <= text.size()) {
            const size_t comma = std::min(text.find(',', start), text.size());
            const std::string item = text.substr(start, comma - start);
            char* end = nullptr;
            const float x = std::strtof(item.c_str(), &end);
            if (item.empty() || *end) throw ParamError(t.set, f.name, "must be a comma-separated list of numbers", "'" + item + "'");
            v.push_back(x);
            start = comma + 1;
        }
        **list = v;
        return;
    }
    throw ParamError(t.set, f.name, "is not set from text");
}

// ParamError for the first field out of its range (the table's order), else nothing.
template <class S>
void validateParams(const S& s, const ParamTable<S>& t) {
    S& m = const_cast<S&>(s);  // read only: ParamRef has no const alternatives
    for (const auto& f : t) {
        const ParamRef r = f.at(m);
        if (const int* const* i = std::get_if<int*>(&r); i && !f.range.allows(**i, false))
            throw ParamError(t.set, f.name, f.range.rule(false), std::to_string(**i));
        if (const uint32_t* const* u = std::get_if<uint32_t*>(&r); u && !f.range.allows(**u, false))
            throw ParamError(t.set, f.name, f.range.rule(false), std::to_string(**u));
        if (const float* const* x = std::get_if<float*>(&r); x && !f.range.allows(**x, true))
            throw ParamError(t.set, f.name, f.range.rule(true), formatParamNumber(**x));
        if (f.check)
            if (std::string why = f.check(s); !why.empty()) throw ParamError(t.set, f.name, why);
        if (const std::vector<float>* const* l = std::get_if<std::vector<float>*>(&r))
            for (float x : **l)
                if (!f.range.allows(x, true)) throw ParamError(t.set, f.name, f.range.rule(true), formatParamNumber(x));
    }
}

// Every field of the table equal (floats compared as floats: NaN differs from everything).
template <class S>
bool sameParams(const S& a, const S& b, const ParamTable<S>& t) {
    S& x = const_cast<S&>(a);
    S& y = const_cast<S&>(b);
    for (const auto& f : t) {
        const bool same = std::visit([&](auto* p) { return *p == *std::get<decltype(p)>(f.at(y)); }, f.at(x));
        if (!same) return false;
    }
    return true;
}

}  // namespace atrous
