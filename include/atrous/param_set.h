// A parameter table together with values of its struct, without the struct's type: what a
// sequence method's registry row declares (atrous/sequence_methods.h: its table and defaults, a
// plugin's struct as much as SvgfParams) and what a front-end fills from its flags, keywords or
// controls and hands to the method. The table is params.h's ParamTable<S> (one row per field:
// name, range, doc, flag); the set holds an S of its own, or, bound (ParamSet::bind), writes
// into the caller's. The CLI's flags, Python's keywords and the viewer's controls walk its rows,
// so a method's table reaches every front-end without any of them knowing its struct.
#pragma once
#include <memory>
#include <string>
#include <typeinfo>
#include <utility>
#include <vector>

#include "atrous/params.h"

namespace atrous {

// One row of a ParamSet's table: its ParamField without the struct's type.
struct ParamRow {
    const char* name;            // snake_case: the keyword, the CLI flag's tail, the name in messages
    ParamRange range;            // Int, Float, UInt and a FloatList's elements
    const char* doc;             // one line
    const char* group;           // the nested struct, "" for the struct's own fields
    bool negated;                // Bool: the CLI flag --no-<name> clears it
    const char* const* choices;  // Choice: the names of the values, null-ended
    ParamKind kind;
    std::string flag;            // the CLI flag, "--svgf-alpha" ("" = none)
};

class ParamSet {
public:
    ParamSet() = default;  // no parameters (a method without a table)
    // A set of `table`'s struct holding its own copy of `values` (the struct's defaults unless
    // given). The table must outlive the set (the tables of params.h and a plugin's are static).
    template <class S>
    explicit ParamSet(const ParamTable<S>& table, const S& values = S{});
    // A set that reads and writes the caller's `values` in place (a CLI's flags write there); it
    // must not outlive them. A copy of it owns a copy of the values.
    template <class S>
    static ParamSet bind(const ParamTable<S>& table, S& values);

    ParamSet(const ParamSet& other);
    ParamSet& operator=(const ParamSet& other);
    ParamSet(ParamSet&&) noexcept = default;
    ParamSet& operator=(ParamSet&&) noexcept = default;
    ~ParamSet() = default;

    // A set bound to this one's values (as bind() to a struct): it must not outlive this set.
    ParamSet view() const { return mModel ? ParamSet(mModel->view()) : ParamSet(); }

    bool empty() const { return !mModel; }
    const char* set() const;                    // the table's name (ParamError::set): "svgf"; "" when empty
    const std::vector<ParamRow>& rows() const;  // in the table's order; none when empty
    int find(const std::string& name) const;    // the row of that name, -1 when none
    // Where row `i`'s value is, in this set's struct (read it, or write through it).
    ParamRef at(size_t i) const;
    // Sets a Choice from its name or a FloatList from "0,0.5,1" (setParamFromText): ParamError
    // naming the field otherwise.
    void setText(size_t i, const std::string& text);
    void validate() const;                 // ParamError for the first field out of its range
    bool same(const ParamSet& other) const;  // the same table, every field equal (sameParams)
    // The struct, when the set's is an S; null otherwise (the method's own code reads it so).
    template <class S>
    const S* get() const {
        return mModel ? static_cast<const S*>(mModel->values(typeid(S))) : nullptr;
    }
    template <class S>
    S* get() {
        return mModel ? static_cast<S*>(const_cast<void*>(mModel->values(typeid(S)))) : nullptr;
    }

private:
    struct Model {
        virtual ~Model() = default;
        virtual std::unique_ptr<Model> copy() const = 0;  // owns a copy of the values
        virtual std::unique_ptr<Model> view() const = 0;  // bound to these values
        virtual ParamRef at(size_t i) const = 0;
        virtual void setText(size_t i, const std::string& text) = 0;
        virtual void validate() const = 0;
        virtual bool same(const Model& other) const = 0;
        virtual const void* values(const std::type_info& type) const = 0;  // null unless the struct is `type`
        const char* set = "";
        std::vector<ParamRow> rows;
    };
    template <class S>
    struct ModelOf;
    explicit ParamSet(std::unique_ptr<Model> m) : mModel(std::move(m)) {}
    std::unique_ptr<Model> mModel;
};

template <class S>
struct ParamSet::ModelOf : ParamSet::Model {
    const ParamTable<S>* table;
    S own{};
    S* data;  // &own, or the caller's (bind)
    ModelOf(const ParamTable<S>& t, const S& v) : table(&t), own(v), data(&own) { describe(); }
    ModelOf(const ParamTable<S>& t, S* external) : table(&t), data(external) { describe(); }
    void describe() {
        set = table->set;
        for (const ParamField<S>& f : *table)
            rows.push_back({f.name, f.range, f.doc, f.group, f.negated, f.choices, f.kind(), table->flag(f)});
    }
    std::unique_ptr<Model> copy() const override { return std::make_unique<ModelOf>(*table, *data); }
    std::unique_ptr<Model> view() const override { return std::make_unique<ModelOf>(*table, data); }
    ParamRef at(size_t i) const override { return table->first[i].at(*data); }
    void setText(size_t i, const std::string& text) override { setParamFromText(*data, *table, table->first[i], text); }
    void validate() const override { validateParams(*data, *table); }
    bool same(const Model& other) const override {
        const S* o = static_cast<const S*>(other.values(typeid(S)));
        return o && sameParams(*data, *o, *table);
    }
    const void* values(const std::type_info& type) const override { return type == typeid(S) ? data : nullptr; }
};

template <class S>
ParamSet::ParamSet(const ParamTable<S>& table, const S& values) : mModel(std::make_unique<ModelOf<S>>(table, values)) {}

template <class S>
ParamSet ParamSet::bind(const ParamTable<S>& table, S& values) {
    return ParamSet(std::make_unique<ModelOf<S>>(table, &values));
}

inline ParamSet::ParamSet(const ParamSet& other) : mModel(other.mModel ? other.mModel->copy() : nullptr) {}
inline ParamSet& ParamSet::operator=(const ParamSet& other) {
    if (this != &other) mModel = other.mModel ? other.mModel->copy() : nullptr;
    return *this;
}
inline const char* ParamSet::set() const { return mModel ? mModel->set : ""; }
inline const std::vector<ParamRow>& ParamSet::rows() const {
    static const std::vector<ParamRow> none;
    return mModel ? mModel->rows : none;
}
inline int ParamSet::find(const std::string& name) const {
    const std::vector<ParamRow>& r = rows();
    for (size_t i = 0; i < r.size(); ++i)
        if (name == r[i].name) return int(i);
    return -1;
}
inline ParamRef ParamSet::at(size_t i) const { return mModel->at(i); }
inline void ParamSet::setText(size_t i, const std::string& text) { mModel->setText(i, text); }
inline void ParamSet::validate() const {
    if (mModel) mModel->validate();
}
inline bool ParamSet::same(const ParamSet& other) const {
    if (!mModel || !other.mModel) return !mModel && !other.mModel;
    return mModel->same(*other.mModel);
}

// A negated switch's CLI name as a keyword (Python's): --no-firefly -> no_firefly.
inline std::string negatedKeyword(const ParamRow& r) {
    std::string k = r.flag.size() > 2 ? r.flag.substr(2) : r.flag;
    for (char& c : k)
        if (c == '-') c = '_';
    return k;
}

// Every name a set's rows take in Python: each row's name, and a negated switch's negatedKeyword
// (for "did you mean" after an unknown keyword, param_table.h's didYouMean).
inline std::vector<std::string> paramKeywords(const ParamSet& set) {
    std::vector<std::string> names;
    for (const ParamRow& r : set.rows()) {
        names.push_back(r.name);
        if (r.negated && r.flag.size() > 2) names.push_back(negatedKeyword(r));
    }
    return names;
}

}  // namespace atrous
