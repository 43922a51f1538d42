/* PLACEHOLDER: replaced by the real subcommand. */
#include "cli/cli.h"
#include "cli/commands.h"

int cmd_info(int argc, char **argv, struct cli_env *env)
{
    (void)argc;
    (void)argv;
    return cli_usage_error(env, "not implemented yet");
}
