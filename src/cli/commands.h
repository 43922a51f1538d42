/*
 * Subcommands: one file each, src/cli/cmd_<name>.c (STYLE.md section 10).
 * The return value is the process exit status.
 */
#ifndef ASP_CLI_COMMANDS_H
#define ASP_CLI_COMMANDS_H

struct cli_env;

int cmd_info(int argc, char **argv, struct cli_env *env);
int cmd_convert(int argc, char **argv, struct cli_env *env);
int cmd_sample(int argc, char **argv, struct cli_env *env);
int cmd_synth(int argc, char **argv, struct cli_env *env);
int cmd_estimate(int argc, char **argv, struct cli_env *env);
int cmd_render(int argc, char **argv, struct cli_env *env);
int cmd_imgdiff(int argc, char **argv, struct cli_env *env);
int cmd_decompose(int argc, char **argv, struct cli_env *env);
int cmd_build(int argc, char **argv, struct cli_env *env);
int cmd_view(int argc, char **argv, struct cli_env *env);
int cmd_eval(int argc, char **argv, struct cli_env *env);
int cmd_simplify(int argc, char **argv, struct cli_env *env);
int cmd_fit(int argc, char **argv, struct cli_env *env);
int cmd_bench_paper(int argc, char **argv, struct cli_env *env);
int cmd_export(int argc, char **argv, struct cli_env *env);
int cmd_scene(int argc, char **argv, struct cli_env *env);
int cmd_experiment(int argc, char **argv, struct cli_env *env);
/* the experiment's analysis (src/cli/cmd_experiment_analyze.c, cmd_experiment_ttest.c), called by cmd_experiment */
int cmd_experiment_analyze(int argc, char **argv, struct cli_env *env);
int cmd_experiment_ttest(int argc, char **argv, struct cli_env *env);

#endif
