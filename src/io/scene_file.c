/* The scene files' YAML syntax, checked before PETSc reads them: PETSc 3.18 reports a syntax error as "YAML parser
   loading error" with a traceback and no position; here the file, line, column and libyaml's explanation. Runs
   before MPI and PETSc are initialised (every rank checks; rank 0 of the launcher prints).
   The same pass records where each option of a scene or options file comes from (file and line), flattened as PETSc
   flattens a YAML scene (nested keys joined by '_'), so that a message about an option can name its file and line
   (PhlexOptionsOrigin); solver presets are added when they are inserted (PhlexOptionsOriginAddFile). */
#include <phlex_impl.h>
#include <yaml.h>
#include <errno.h>
#include <sys/stat.h>
#include <ctype.h>
#include <strings.h>

/* one option of a file: its name (without '-'), its value, the file, the line (from 1), and whether a solver preset
   gave it (under the scenes and the command line) */
typedef struct {
  char *name, *value, *file;
  int   line, preset;
} Origin;

static Origin *origins;
static int     norigins, maxorigins;

static char *Dup(const char *s)
{
  const size_t n = strlen(s ? s : "");
  char        *d = malloc(n + 1);
  if (d) memcpy(d, s ? s : "", n + 1);
  return d;
}

/* plain C (before PetscInitialize and after PetscFinalize): a failed allocation loses the origin, not the run */
static void RecordOrigin(const char *name, const char *value, const char *file, int line, int preset)
{
  if (norigins == maxorigins) {
    const int n   = maxorigins ? 2 * maxorigins : 64;
    Origin   *tmp = realloc(origins, (size_t)n * sizeof(Origin));
    if (!tmp) return;
    origins    = tmp;
    maxorigins = n;
  }
  origins[norigins].name   = Dup(name);
  origins[norigins].value  = Dup(value);
  origins[norigins].file   = Dup(file);
  origins[norigins].line   = line;
  origins[norigins].preset = preset;
  if (origins[norigins].name && origins[norigins].value && origins[norigins].file) norigins++;
  else {
    free(origins[norigins].name);
    free(origins[norigins].value);
    free(origins[norigins].file);
  }
}

/* a YAML mapping as PETSc 3.18 reads it (PetscParseLayerYAML): key: scalar is -<prefix>key, key: [a, b] is
   -<prefix>key a,b, key: {mapping} pushes the prefix <prefix>key_, '<<' merges without a prefix, '$$' keys are
   skipped */
static void RecordLayer(yaml_document_t *doc, yaml_node_t *node, const char *prefix, const char *file, int depth)
{
  if (!node || node->type != YAML_MAPPING_NODE || depth > 32) return;
  for (yaml_node_pair_t *pair = node->data.mapping.pairs.start; pair < node->data.mapping.pairs.top; pair++) {
    yaml_node_t *key = yaml_document_get_node(doc, pair->key), *value = yaml_document_get_node(doc, pair->value);
    const char  *k;
    char         name[512];
    if (!key || !value || key->type != YAML_SCALAR_NODE) continue;
    k = (const char *)key->data.scalar.value;
    if (!strcmp(k, "<<")) {
      if (value->type == YAML_MAPPING_NODE) RecordLayer(doc, value, prefix, file, depth + 1);
      else if (value->type == YAML_SEQUENCE_NODE)
        for (yaml_node_item_t *item = value->data.sequence.items.start; item < value->data.sequence.items.top; item++) RecordLayer(doc, yaml_document_get_node(doc, *item), prefix, file, depth + 1);
      continue;
    }
    if (!strncmp(k, "$$", 2)) continue;
    snprintf(name, sizeof(name), "%s%s", prefix, k);
    if (value->type == YAML_MAPPING_NODE) {
      const size_t n = strlen(name);
      if (n + 2 > sizeof(name)) continue; /* a key path of 500 characters: no option has it */
      name[n]     = '_';
      name[n + 1] = 0;
      RecordLayer(doc, value, name, file, depth + 1);
    } else if (value->type == YAML_SEQUENCE_NODE) {
      char   list[1024] = "";
      size_t n          = 0;
      for (yaml_node_item_t *item = value->data.sequence.items.start; item < value->data.sequence.items.top; item++) {
        yaml_node_t *it = yaml_document_get_node(doc, *item);
        if (it && it->type == YAML_SCALAR_NODE && n < sizeof(list)) n += (size_t)snprintf(list + n, sizeof(list) - n, "%s%s", n ? "," : "", (const char *)it->data.scalar.value);
      }
      RecordOrigin(name, list, file, (int)key->start_mark.line + 1, 0);
    } else RecordOrigin(name, (const char *)value->data.scalar.value, file, (int)key->start_mark.line + 1, 0);
  }
}

/* a plain options file: every -name on a line (its value: the next word unless that is an option), '#' to the end
   of the line a comment */
static void RecordPlainFile(const char *file, int preset)
{
  FILE *fp = fopen(file, "r");
  char  line[4096];
  int   number = 0;

  if (!fp) return;
  while (fgets(line, sizeof(line), fp)) {
    char *c = line, *hash = strchr(line, '#');
    number++;
    if (hash) *hash = 0;
    while (*c) {
      char *name, *value = NULL, save;
      while (isspace((unsigned char)*c)) c++;
      if (*c != '-' || !isalpha((unsigned char)c[1])) {
        while (*c && !isspace((unsigned char)*c)) c++;
        continue;
      }
      name = c + 1;
      while (*c && !isspace((unsigned char)*c)) c++;
      save = *c;
      *c   = 0;
      if (save) {
        char *v = c + 1, *ve;
        while (isspace((unsigned char)*v)) v++;
        if (*v && !(*v == '-' && isalpha((unsigned char)v[1]))) {
          for (ve = v; *ve && !isspace((unsigned char)*ve); ve++) {}
          if (*ve) *ve++ = 0;
          value = v;
          RecordOrigin(name, value, file, number, preset);
          c = ve;
          continue;
        }
        c++;
      }
      RecordOrigin(name, "", file, number, preset);
    }
  }
  fclose(fp);
}

/*@C
  PhlexOptionsOriginAddFile - records the options of a solver preset (a plain options file) that phlex inserts under
  the scene and the command line, for PhlexOptionsOrigin

  Not collective
@*/
PetscErrorCode PhlexOptionsOriginAddFile(const char file[])
{
  PetscFunctionBeginUser;
  for (int i = 0; i < norigins; i++)
    if (origins[i].preset && !strcmp(origins[i].file, file)) PetscFunctionReturn(0); /* once */
  RecordPlainFile(file, 1);
  PetscFunctionReturn(0);
}

/*@C
  PhlexOptionsOrigin - where an option (name without '-') was given: the last scene or options file of the command line
  that gives it, else the solver preset; file NULL if none (the command line, PETSC_OPTIONS or a petscrc file)

  Not collective

  Output Parameters:
+ file   - the file (NULL: no file recorded gives it)
. line   - its line (from 1)
. value  - the value the file gives
- preset - whether the file is a solver preset
@*/
PetscErrorCode PhlexOptionsOrigin(const char name[], const char **file, int *line, const char **value, PetscBool *preset)
{
  PetscFunctionBeginUser;
  *file = NULL;
  if (line) *line = 0;
  if (value) *value = NULL;
  if (preset) *preset = PETSC_FALSE;
  for (int pass = 0; pass < 2 && !*file; pass++)
    for (int i = norigins - 1; i >= 0; i--) {
      if (origins[i].preset != pass || strcasecmp(origins[i].name, name)) continue;
      *file = origins[i].file;
      if (line) *line = origins[i].line;
      if (value) *value = origins[i].value;
      if (preset) *preset = pass ? PETSC_TRUE : PETSC_FALSE;
      break;
    }
  PetscFunctionReturn(0);
}

/*@C
  PhlexOptionsOriginFree - frees the recorded origins (at the end of main)

  Not collective
@*/
void PhlexOptionsOriginFree(void)
{
  for (int i = 0; i < norigins; i++) {
    free(origins[i].name);
    free(origins[i].value);
    free(origins[i].file);
  }
  free(origins);
  origins  = NULL;
  norigins = maxorigins = 0;
}

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
      if (!code && root) RecordLayer(&document, (yaml_node_t *)root, "", file, 0);
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
  *.yml, -options_file_yaml) and records where each option of those files and of plain options files comes from;
  returns 0, or the exit code after printing the error

  Not collective; called before PetscInitialize
@*/
int PhlexSceneFilesCheck(int argc, char **argv)
{
  for (int i = 1; i + 1 < argc; i++) {
    const int yaml_option = !strcmp(argv[i], "-options_file_yaml");
    if (!yaml_option && strcmp(argv[i], "-options_file")) continue;
    {
      /* PETSc would stop with its traceback (exit 83) on a directory or a plain options file it cannot open (a
         scene file's is CheckYAML's) */
      struct stat st;
      FILE       *fp;
      const int   yaml = yaml_option || EndsWith(argv[i + 1], ".yaml") || EndsWith(argv[i + 1], ".yml");
      if (stat(argv[i + 1], &st) == 0 && S_ISDIR(st.st_mode)) {
        if (IsRankZero()) fprintf(stderr, "phlex: error: option %s '%s' names a directory, not %s\n", argv[i], argv[i + 1], yaml ? "a scene file" : "an options file");
        return PHLEX_EXIT_INPUT;
      }
      if (!yaml && !(fp = fopen(argv[i + 1], "rb"))) {
        if (IsRankZero()) fprintf(stderr, "phlex: error: cannot read the options file '%s' (option %s): %s\n", argv[i + 1], argv[i], strerror(errno));
        return PHLEX_EXIT_INPUT;
      } else if (!yaml) fclose(fp);
    }
    if (yaml_option || EndsWith(argv[i + 1], ".yaml") || EndsWith(argv[i + 1], ".yml")) {
      const int code = CheckYAML(argv[i], argv[i + 1]);
      if (code) return code;
    } else RecordPlainFile(argv[i + 1], 0);
  }
  return 0;
}
