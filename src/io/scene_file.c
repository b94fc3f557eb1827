/* The scene files' YAML syntax, checked before PETSc reads them: PETSc 3.18 reports a syntax error as "YAML parser
   loading error" with a traceback and no position; here the file, line, column and libyaml's explanation. Runs
   before MPI and PETSc are initialised (every rank checks; rank 0 of the launcher prints). */
#include <phlex_impl.h>
#include <yaml.h>
#include <errno.h>

static int IsRankZero(void)
{
  const char *vars[] = {"OMPI_COMM_WORLD_RANK", "PMI_RANK", "PMIX_RANK", NULL};
  for (int i = 0; vars[i]; i++) {
    const char *r = getenv(vars[i]);
    if (r) return atoi(r) == 0;
  }
  return 1;
}

static int EndsWith(const char *s, const char *suffix)
{
  const size_t n = strlen(s), m = strlen(suffix);
  return n >= m && !strcmp(s + n - m, suffix);
}

/* 0 when the file parses; otherwise the message is printed and PHLEX_EXIT_INPUT returned */
static int CheckYAML(const char *option, const char *file)
{
  FILE         *fp = fopen(file, "rb");
  yaml_parser_t parser;
  yaml_document_t document;
  int           done = 0, code = 0, first = 1;

  if (!fp) {
    if (IsRankZero()) fprintf(stderr, "phlex: error: cannot read the scene file '%s' (option %s): %s\n", file, option, strerror(errno));
    return PHLEX_EXIT_INPUT;
  }
  if (!yaml_parser_initialize(&parser)) {
    fclose(fp);
    return 0; /* out of memory: PETSc will report it */
  }
  yaml_parser_set_input_file(&parser, fp);
  while (!done) {
    if (!yaml_parser_load(&parser, &document)) {
      if (IsRankZero()) {
        fprintf(stderr, "phlex: error: scene file '%s' (option %s): YAML syntax error at line %lu, column %lu: %s", file, option, (unsigned long)parser.problem_mark.line + 1, (unsigned long)parser.problem_mark.column + 1, parser.problem ? parser.problem : "unknown problem");
        if (parser.context) fprintf(stderr, " (%s at line %lu)", parser.context, (unsigned long)parser.context_mark.line + 1);
        fprintf(stderr, "\n");
      }
      code = PHLEX_EXIT_INPUT;
      break;
    }
    {
      /* PETSc reads a scene as one mapping of options (key: value, nested mappings for prefixes): an empty file or
         another top level (a list, a bare value) is refused here with the file named, not by PETSc's parser */
      const yaml_node_t *root = yaml_document_get_root_node(&document);
      if (first && !root) {
        if (IsRankZero()) fprintf(stderr, "phlex: error: scene file '%s' (option %s) is empty: a scene is a mapping of options (key: value; see options/*.yaml)\n", file, option);
        code = PHLEX_EXIT_INPUT;
      } else if (root && root->type != YAML_MAPPING_NODE) {
        if (IsRankZero()) fprintf(stderr, "phlex: error: scene file '%s' (option %s): its top level (line %lu) is a %s, not a mapping of options (key: value; see options/*.yaml)\n", file, option, (unsigned long)root->start_mark.line + 1, root->type == YAML_SEQUENCE_NODE ? "list" : "single value");
        code = PHLEX_EXIT_INPUT;
      }
      first = 0;
      done  = !root || code;
    }
    yaml_document_delete(&document);
  }
  yaml_parser_delete(&parser);
  fclose(fp);
  return code;
}

/*@C
  PhlexSceneFilesCheck - checks the YAML syntax of every scene file of the command line (-options_file *.yaml,
  *.yml, -options_file_yaml); returns 0, or the exit code after printing the error

  Not collective; called before PetscInitialize
@*/
int PhlexSceneFilesCheck(int argc, char **argv)
{
  for (int i = 1; i + 1 < argc; i++) {
    const int yaml_option = !strcmp(argv[i], "-options_file_yaml");
    if (!yaml_option && strcmp(argv[i], "-options_file")) continue;
    if (yaml_option || EndsWith(argv[i + 1], ".yaml") || EndsWith(argv[i + 1], ".yml")) {
      const int code = CheckYAML(argv[i], argv[i + 1]);
      if (code) return code;
    }
  }
  return 0;
}
