// The option table (`neepp list`, the CLI's -I help) against the factory: every option it lists is
// accepted with its listed default, and every option the factory reads is listed.
#include <gtest/gtest.h>
#include <set>
#include <map>
#include "neepp/integrators/factory.h"
#include "neepp/integrators/option_table.h"

using namespace neepp;

namespace {

std::set<std::string> listed(const std::string &integrator) {
    std::set<std::string> names;
    for (const IntegratorDoc &d : integrator_docs())
        if (d.name == integrator)
            for (const OptionDoc &o : d.options) names.insert(o.name);
    return names;
}

}  // namespace

TEST(OptionTable, EveryListedOptionIsAcceptedWithItsDefault) {
    ASSERT_EQ(integrator_docs().size(), 5u);
    for (const IntegratorDoc &d : integrator_docs()) {
        EXPECT_FALSE(d.description.empty()) << d.name;
        for (const OptionDoc &o : d.options) {
            Options options;
            std::string value = o.default_value;
            if (o.name == "strategy") value = "2,2";
            if (o.name == "visibility_map") value = "unused.map";
            options.set(o.name, value);
            if (!o.needs.empty()) {
                const auto eq = o.needs.find('=');
                ASSERT_NE(eq, std::string::npos) << o.needs;
                std::string needed = o.needs.substr(eq + 1);
                if (needed.back() == '*') needed.pop_back();  // "neepp*": any NEE++ policy; neepp is one
                if (needed == "S,T") needed = "2,2";
                if (needed == "M") needed = "4";  // ris=M: any number of candidates above 1
                options.set(o.needs.substr(0, eq), needed);
            }
            EXPECT_NO_THROW(make_integrator(d.name, options)) << d.name << " -I " << o.name << "=" << value;
            EXPECT_FALSE(o.description.empty()) << o.name;
        }
    }
}

TEST(OptionTable, EveryOptionTheFactoryReadsIsListed) {
    using Map = std::map<std::string, std::string>;
    const std::vector<std::pair<std::string, Map>> configurations = {
        {"path", {{"shadow_rays", "neepp-adaptive"}, {"light_sampler", "visibility"}}},
        {"path", {{"shadow_rays", "neepp"}, {"nee", "true"}}},
        {"path", {{"ris", "8"}}},
        {"volpath", {{"shadow_rays", "neepp-adaptive"}, {"light_sampler", "visibility"}}},
        {"bdpt", {{"light_paths", "neepp"}, {"shadow_rays", "neepp-adaptive"}}},
        {"bdpt", {{"strategy", "1,2"}, {"strategy_weight", "none"}}},
        {"light", {{"shadow_rays", "neepp-adaptive"}}},
        {"pssmlt", {{"shadow_rays", "neepp"}}},
        {"pssmlt", {{"bidirectional", "false"}, {"shadow_rays", "neepp-adaptive"}}},
    };
    for (const auto &[name, values] : configurations) {
        Options options{Map(values)};
        make_integrator(name, options);
        std::set<std::string> known = listed(name);
        if (name == "pssmlt") {  // and the options of the integrator it runs over
            const auto over = listed(values.count("bidirectional") ? "path" : "bdpt");
            known.insert(over.begin(), over.end());
        }
        for (const std::string &key : options.asked()) EXPECT_TRUE(known.count(key)) << name << " reads '" << key << "', not in its table";
    }
}

// A number option of nan or inf (from -I or a scene's integrator) is refused naming the option and the
// value, as a misspelt number is: no option means anything by them.
TEST(OptionTable, NonFiniteNumbersAreRefused) {
    for (const char *value : {"nan", "inf", "-inf", "1e39"}) {
        Options o;
        o.set("shadow_rays", "neepp");
        o.set("q_min", value);
        try {
            make_integrator("path", o);
            ADD_FAILURE() << "q_min=" << value << " was accepted";
        } catch (const std::invalid_argument &e) {
            const std::string msg = e.what();
            EXPECT_NE(msg.find("q_min"), std::string::npos) << msg;
            EXPECT_NE(msg.find(std::string("'") + value + "'"), std::string::npos) << msg;
        }
    }
}

// An option another option's setting turns on (the table's `needs`), given without it, is refused saying
// which setting reads it; an option no integrator knows is refused plainly.
TEST(OptionTable, AnOptionReadOnlyWithAnotherSaysWhich) {
    try {
        make_integrator("path", Options(std::map<std::string, std::string>{{"auto_guiding", "true"}, {"bogus", "1"}}));
        ADD_FAILURE() << "auto_guiding without neepp=auto was accepted";
    } catch (const std::invalid_argument &e) {
        const std::string what = e.what();
        EXPECT_NE(what.find("auto_guiding (read only with -I neepp=auto)"), std::string::npos) << what;
        EXPECT_NE(what.find("bogus"), std::string::npos) << what;
        EXPECT_EQ(what.find("bogus ("), std::string::npos) << what;
    }
}
