/*
 * The seed presets (issue 17, include/amgsplat/preset.h): every name parses
 * back to its preset, unknown names are refused with the valid ones named,
 * and every setting names a command that takes --preset, an option and the
 * seed section it comes from. The values a command accepts are checked by
 * tests/cli/seeds_*.sh, which run them.
 */
#include "amgsplat/preset.h"
#include "harness.h"

static void test_names(void)
{
    for (int p = 0; p < ASP_PRESET_COUNT; p++) {
        const char *name = asp_preset_name((asp_preset)p);
        CHECK(name != NULL);
        asp_preset back = ASP_PRESET_COUNT;
        CHECK(asp_preset_parse(name, &back, NULL) == 0);
        CHECK(back == (asp_preset)p);
    }
    CHECK(asp_preset_name(ASP_PRESET_COUNT) == NULL);
    asp_error err = {0, ""};
    asp_preset out = ASP_PRESET_THESIS;
    CHECK(asp_preset_parse("Journal", &out, &err) == ASP_EINVAL); /* names are exact, as option values are */
    CHECK(out == ASP_PRESET_THESIS);                                /* unchanged on failure */
    CHECK(strstr(err.msg, "'Journal'") != NULL);
    CHECK(strstr(err.msg, "pajarola") != NULL);
    CHECK(asp_preset_parse(NULL, &out, NULL) == ASP_EINVAL);
}

static void test_settings(void)
{
    static const char *const commands[] = {"decompose", "build", "render", "view"};
    size_t count = 1;
    CHECK(asp_preset_settings(ASP_PRESET_NONE, &count) == NULL && count == 0);
    CHECK(asp_preset_settings(ASP_PRESET_COUNT, &count) == NULL && count == 0);
    for (int p = 1; p < ASP_PRESET_COUNT; p++) {
        const asp_preset_setting *s = asp_preset_settings((asp_preset)p, &count);
        CHECK_MSG(s && count > 0, "preset %s is empty", asp_preset_name((asp_preset)p));
        for (size_t k = 0; s && k < count; k++) {
            int known = 0;
            for (size_t c = 0; c < sizeof commands / sizeof commands[0]; c++)
                known |= strcmp(s[k].command, commands[c]) == 0;
            CHECK_MSG(known, "%s: command '%s'", asp_preset_name((asp_preset)p), s[k].command);
            CHECK(s[k].option && s[k].option[0] && s[k].option[0] != '-');
            CHECK(s[k].source && s[k].source[0]);
            /* one value per option and command: a repeated option would silently override its twin */
            for (size_t j = 0; j < k; j++)
                CHECK_MSG(strcmp(s[j].command, s[k].command) || strcmp(s[j].option, s[k].option),
                          "%s sets %s --%s twice", asp_preset_name((asp_preset)p), s[k].command, s[k].option);
        }
    }
    /* the journal's own numbers (journal 2.1-2.3) */
    const asp_preset_setting *j = asp_preset_settings(ASP_PRESET_JOURNAL, &count);
    int seen = 0;
    for (size_t k = 0; k < count; k++) {
        if (strcmp(j[k].command, "decompose") == 0 && strcmp(j[k].option, "classifier") == 0)
            seen += strcmp(j[k].value, "moment") == 0;
        if (strcmp(j[k].command, "decompose") == 0 && strcmp(j[k].option, "alpha") == 0)
            seen += strtod(j[k].value, NULL) == 0.01;
        if (strcmp(j[k].command, "decompose") == 0 && strcmp(j[k].option, "beta") == 0)
            seen += strtod(j[k].value, NULL) == 100;
        if (strcmp(j[k].command, "decompose") == 0 && strcmp(j[k].option, "k") == 0)
            seen += strtod(j[k].value, NULL) >= 50 && strtod(j[k].value, NULL) <= 100;
        if (strcmp(j[k].command, "build") == 0 && strcmp(j[k].option, "level") == 0)
            seen += strcmp(j[k].value, "L-5") == 0;
    }
    CHECK_MSG(seen == 5, "journal preset: %d of 5 seed values found", seen);
}

TEST_MAIN(TEST_CASE(test_names), TEST_CASE(test_settings))
