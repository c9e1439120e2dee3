/*
 * clpt_docs.c — writes what the shell and `man` need to know about clpt's command line,
 * from the one list of flags (host/options.c's OPTIONS(X), read through options.h):
 *
 *   clpt_docs man    the man page clpt.1 (roff), to stdout
 *   clpt_docs bash   the bash completion script
 *   clpt_docs zsh    the zsh completion function (_clpt)
 *
 * The Makefile runs it into build/ and `make install` installs the results, so a new
 * flag reaches --help, the man page and both completions without anyone editing them.
 * The texts are --help's own (section headings, prose, each flag's lines), reflowed.
 */
#include <stddef.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "options.h"
#include "version.h"

/* ------------------------------------------------------------------ roff */

/* Text for a roff line: backslashes as \e, every '-' as \- (options stay copyable, and
 * a hyphen in prose renders the same), and a control character at the line's start
 * ('.' or '\'') neutralised by \&. */
static void roff_text(FILE *f, const char *s, size_t n, int line_start)
{
    for (size_t i = 0; i < n && s[i]; i++) {
        char c = s[i];
        if (line_start && i == 0 && (c == '.' || c == '\'')) fputs("\\&", f);
        if (c == '\\') fputs("\\e", f);
        else if (c == '-') fputs("\\-", f);
        else fputc(c, f);
    }
}

/* One line of a section text, without its newline; *p moves past it. */
static size_t next_line(const char **p, const char **line)
{
    *line = *p;
    size_t n = strcspn(*p, "\n");
    *p += n + (((*p)[n] == '\n') ? 1 : 0);
    return n;
}

/* A heading line of --help: not indented, ending in ':'. */
static int is_heading(const char *line, size_t n)
{
    return n > 1 && line[0] != ' ' && line[n - 1] == ':';
}

/* A heading without its ':' and, when it is only a pointer to the docs, without its
 * "(docs/...)": "Exit status (docs/exit-codes.md):" is "EXIT STATUS" at the top level. */
static void roff_heading(FILE *f, const char *macro, const char *line, size_t n, int upper)
{
    char text[256];
    size_t len = n - 1 < sizeof text - 1 ? n - 1 : sizeof text - 1;
    memcpy(text, line, len);
    text[len] = '\0';
    char *paren = strstr(text, " (docs/");
    if (paren && paren[strlen(paren) - 1] == ')') *paren = '\0';
    for (char *c = text; upper && *c; c++)
        if (*c >= 'a' && *c <= 'z') *c = (char)(*c - 'a' + 'A');
    fprintf(f, "%s ", macro);
    roff_text(f, text, strlen(text), 1);
    fputc('\n', f);
}

/* A section's text after its usage lines: headings (.SH at the top level, else .SS),
 * prose lines filled into paragraphs, indented lines (tables) kept as they are. */
static void roff_section_text(FILE *f, const char *text, int top_level)
{
    enum { NONE, PROSE, TABLE } mode = NONE;
    const char *p = text, *line;
    while (*p) {
        size_t n = next_line(&p, &line);
        int table = n > 0 && line[0] == ' ';
        if (mode == TABLE && !table) fputs(".fi\n", f);
        if (n == 0) {
            mode = NONE;
            continue;
        }
        if (is_heading(line, n)) {
            roff_heading(f, top_level ? ".SH" : ".SS", line, n, top_level);
            mode = NONE;
            continue;
        }
        if (table && mode != TABLE) fputs(".PP\n.nf\n", f);
        if (!table && mode != PROSE) fputs(".PP\n", f);
        mode = table ? TABLE : PROSE;
        /* the tables keep --help's columns less its two-space margin: man indents */
        if (table && n >= 2) {
            line += 2;
            n -= 2;
        }
        roff_text(f, line, n, 1);
        fputc('\n', f);
    }
    if (mode == TABLE) fputs(".fi\n", f);
}

/* The usage lines ("usage: clpt ...", then lines indented to match) as the SYNOPSIS;
 * returns the text after them. */
static const char *roff_synopsis(FILE *f, const char *intro)
{
    static const char usage[] = "usage: ";
    fputs(".SH SYNOPSIS\n.nf\n", f);
    const char *p = intro, *line;
    while (*p) {
        size_t n = next_line(&p, &line);
        if (n == 0) break;
        size_t skip = strncmp(line, usage, sizeof usage - 1) == 0 ? sizeof usage - 1 : 0;
        if (!skip && n >= sizeof usage - 1 && strspn(line, " ") >= sizeof usage - 1) skip = sizeof usage - 1;
        roff_text(f, line + skip, n - skip, 1);
        fputc('\n', f);
    }
    fputs(".fi\n", f);
    return p;
}

/* One flag: its names and value as the tag, its help lines as one paragraph. */
static void roff_flag(FILE *f, const OptionSpec *s)
{
    char value[128];
    option_value_text(s, value, sizeof value);
    fputs(".TP\n", f);
    if (s->alias) {
        fputs("\\fB", f);
        roff_text(f, s->alias, strlen(s->alias), 0);
        fputs("\\fR, ", f);
    }
    fputs("\\fB", f);
    roff_text(f, s->name, strlen(s->name), 0);
    fputs("\\fR", f);
    if (value[0]) {
        /* " FILE" or "[=text|json]": the words in italics */
        size_t lead = strspn(value, " [=");
        roff_text(f, value, lead, 0);
        fputs("\\fI", f);
        roff_text(f, value + lead, strcspn(value + lead, "]"), 0);
        fputs("\\fR", f);
        if (value[strlen(value) - 1] == ']') fputc(']', f);
    }
    fputc('\n', f);
    const char *p = s->help, *line;
    for (int first = 1; *p; first = 0) {
        size_t n = next_line(&p, &line);
        if (!first) fputc(' ', f);
        roff_text(f, line, n, first);
    }
    fputc('\n', f);
}

static void write_man(FILE *f)
{
    size_t n_sections = options_help_sections();
    fprintf(f, ".\\\" clpt.1: written by clpt_docs from the option list in host/options.c; do not edit.\n");
    fprintf(f, ".TH CLPT 1 \"\" \"clpt %s\" \"User Commands\"\n", clpt_version_text);
    /* no hyphenation, ragged right: paths and flag names stay whole and copyable */
    fputs(".nh\n.ad l\n.SH NAME\nclpt \\- a portable OpenCL path tracer\n", f);
    const char *description = roff_synopsis(f, options_help_section(0));
    fputs(".SH DESCRIPTION\n", f);
    roff_section_text(f, description, 0);
    fputs(".SH OPTIONS\n", f);
    for (size_t sec = 1; sec + 1 < n_sections; sec++) {
        roff_section_text(f, options_help_section(sec), 0);
        for (size_t k = 0; options_flag(k); k++)
            if ((size_t)options_flag(k)->section == sec) roff_flag(f, options_flag(k));
    }
    roff_section_text(f, options_help_section(n_sections - 1), 1);
    fputs(".SH SEE ALSO\n"
          "The documentation in clpt's source tree: README.md, docs/cli.md (this command line),\n"
          "docs/scene-format.md, docs/exit-codes.md and the other files of docs/.\n", f);
}

/* ------------------------------------------------------------------ completions */

/* What a flag's value is, for the shells. */
typedef enum { VALUE_NONE, VALUE_WORDS, VALUE_IMAGE, VALUE_FILE, VALUE_DIR, VALUE_DEVICE, VALUE_OTHER } ValueKind;

/* Read from the list: a choice's words; a TEXT flag by what it names (the output,
 * whose name picks the format, by its field). */
static ValueKind value_kind(const OptionSpec *s)
{
    if (s->kind == OPTION_SWITCH) return s->choices ? VALUE_WORDS : VALUE_NONE;
    if (s->kind == OPTION_CHOICE) return VALUE_WORDS;
    if (s->kind != OPTION_TEXT || !s->what) return VALUE_OTHER;
    if (s->offset == offsetof(Options, output)) return VALUE_IMAGE;
    if (strcmp(s->what, "file name") == 0) return VALUE_FILE;
    if (strcmp(s->what, "folder name") == 0) return VALUE_DIR;
    if (strcmp(s->what, "device list") == 0) return VALUE_DEVICE;
    return VALUE_OTHER;
}

static void print_words(FILE *f, const OptionChoice *c)
{
    for (; c->name; c++) fprintf(f, "%s%s", c->name, c[1].name ? " " : "");
}

#define IMAGE_GLOB "png|ppm|bmp|pfm|exr|hdr|PNG|PPM|BMP|PFM|EXR|HDR"
#define SCENE_GLOB "scene|pbrt|txt|gltf|glb|obj|ply"

static void write_bash(FILE *f)
{
    fputs("# bash completion for clpt: written by clpt_docs from the option list in host/options.c.\n"
          "# Installed as share/bash-completion/completions/clpt; or: source clpt.bash\n\n"
          "# Files whose name ends in one of the extensions (an extglob alternation), and folders.\n"
          "_clpt_files() {\n"
          "    local IFS=$'\\n' cur=$1 f\n"
          "    compopt -o filenames 2>/dev/null\n"
          "    COMPREPLY=($(compgen -d -- \"$cur\"))\n"
          "    for f in $(compgen -f -- \"$cur\"); do\n"
          "        [[ -f $f && $f =~ \\.($2)$ ]] && COMPREPLY+=(\"$f\")\n"
          "    done\n"
          "}\n\n"
          "# --device: the groups, and the indices clpt --list-devices prints.\n"
          "_clpt_devices() {\n"
          "    local ids\n"
          "    ids=$(\"$1\" --list-devices 2>/dev/null | awk '$1 ~ /^[0-9]+$/ { print $1 }')\n"
          "    COMPREPLY=($(compgen -W \"all gpu cpu scalar $ids\" -- \"$2\"))\n"
          "}\n\n"
          "_clpt() {\n"
          "    local cur=${COMP_WORDS[COMP_CWORD]} prev=${COMP_WORDS[COMP_CWORD-1]}\n"
          "    COMPREPLY=()\n", f);
    /* --stats=WORD: bash splits the word at '=' (COMP_WORDBREAKS) */
    fputs("    if [[ $cur == = || $prev == = ]]; then\n"
          "        local flag=${COMP_WORDS[COMP_CWORD-1]} word=$cur\n"
          "        [[ $cur == = ]] && word= || flag=${COMP_WORDS[COMP_CWORD-2]}\n"
          "        case $flag in\n", f);
    for (size_t k = 0; options_flag(k); k++) {
        const OptionSpec *s = options_flag(k);
        if (s->kind != OPTION_SWITCH || !s->choices) continue;
        fprintf(f, "            %s) COMPREPLY=($(compgen -W '", s->name);
        print_words(f, s->choices);
        fputs("' -- \"$word\")); return ;;\n", f);
    }
    fputs("        esac\n"
          "        prev=$flag\n"
          "        cur=$word\n"
          "    fi\n"
          "    case $prev in\n", f);
    for (size_t k = 0; options_flag(k); k++) {
        const OptionSpec *s = options_flag(k);
        ValueKind v = value_kind(s);
        if (v == VALUE_NONE || (s->kind == OPTION_SWITCH)) continue;
        /* the alias also ends a bundle of one-letter switches: -qo FILE */
        if (s->alias) fprintf(f, "        %s|%s|-[!-]*%s) ", s->name, s->alias, s->alias + 1);
        else fprintf(f, "        %s) ", s->name);
        switch (v) {
        case VALUE_WORDS:
            fputs("COMPREPLY=($(compgen -W '", f);
            print_words(f, s->choices);
            fputs("' -- \"$cur\"))", f);
            break;
        case VALUE_IMAGE: fputs("_clpt_files \"$cur\" '" IMAGE_GLOB "'", f); break;
        case VALUE_FILE: fputs("compopt -o filenames 2>/dev/null; COMPREPLY=($(compgen -f -- \"$cur\"))", f); break;
        case VALUE_DIR: fputs("compopt -o filenames 2>/dev/null; COMPREPLY=($(compgen -d -- \"$cur\"))", f); break;
        case VALUE_DEVICE: fputs("_clpt_devices \"${COMP_WORDS[0]}\" \"$cur\"", f); break;
        case VALUE_NONE: case VALUE_OTHER: fputs(":", f); break;   /* a number or a name: nothing to offer */
        }
        fputs("; return ;;\n", f);
    }
    fputs("    esac\n"
          "    if [[ $cur == -* ]]; then\n"
          "        COMPREPLY=($(compgen -W '", f);
    for (size_t k = 0; options_flag(k); k++) {
        const OptionSpec *s = options_flag(k);
        fprintf(f, "%s%s%s%s", k ? " " : "", s->name, s->alias ? " " : "", s->alias ? s->alias : "");
    }
    fputs(" --' -- \"$cur\"))\n"
          "        return\n"
          "    fi\n"
          "    _clpt_files \"$cur\" '" SCENE_GLOB "'\n"
          "}\n"
          "complete -F _clpt clpt\n", f);
}

/* A help text's first line as a zsh description: what _arguments reads as syntax
 * (brackets, colons, backslashes) left out, and single quotes doubled for the spec's
 * quoting. */
static void zsh_description(FILE *f, const char *help)
{
    for (const char *p = help; *p && *p != '\n'; p++) {
        if (*p == '[' || *p == ']' || *p == ':' || *p == '\\') continue;
        if (*p == '\'') fputs("'\\''", f);
        else fputc(*p, f);
    }
}

static void zsh_action(FILE *f, const OptionSpec *s)
{
    const char *label = s->metavar ? s->metavar : "value";
    switch (value_kind(s)) {
    case VALUE_WORDS:
        fprintf(f, ":%s:(", s->kind == OPTION_SWITCH ? "format" : "choice");
        print_words(f, s->choices);
        fputc(')', f);
        break;
    case VALUE_IMAGE: fprintf(f, ":%s:_files -g '\\''*.(" IMAGE_GLOB ")'\\''", label); break;
    case VALUE_FILE: fprintf(f, ":%s:_files", label); break;
    case VALUE_DIR: fprintf(f, ":%s:_files -/", label); break;
    case VALUE_DEVICE: fprintf(f, ":%s:_clpt_devices", label); break;
    case VALUE_NONE: break;
    case VALUE_OTHER: fprintf(f, ":%s: ", label); break;
    }
}

static void write_zsh(FILE *f)
{
    fputs("#compdef clpt\n"
          "# zsh completion for clpt: written by clpt_docs from the option list in host/options.c.\n"
          "# Installed as share/zsh/site-functions/_clpt.\n\n"
          "_clpt_devices() {\n"
          "    local -a ids\n"
          "    ids=(all gpu cpu scalar ${(f)\"$(${words[1]} --list-devices 2>/dev/null | awk '$1 ~ /^[0-9]+$/ { print $1 }')\"})\n"
          "    compadd -a ids\n"
          "}\n\n"
          "_clpt() {\n"
          "    _arguments -s -S \\\n", f);
    for (size_t k = 0; options_flag(k); k++) {
        const OptionSpec *s = options_flag(k);
        int takes = s->kind != OPTION_SWITCH;
        /* a switch with words takes one only after '=' (--stats=json), and may not */
        const char *suffix = takes ? "=" : s->choices ? "=-" : "";
        fputs("        '", f);
        if (s->alias) fprintf(f, "(%s %s)'{%s%s,%s%s}'", s->alias, s->name, s->alias, takes ? "+" : "", s->name, suffix);
        else fprintf(f, "%s%s", s->name, suffix);
        fputc('[', f);
        zsh_description(f, s->help);
        fputc(']', f);
        if (s->kind == OPTION_SWITCH && s->choices) fputc(':', f);   /* optional: "::" */
        zsh_action(f, s);
        fputs("' \\\n", f);
    }
    fputs("        '*:scene file:_files -g \"*.(" SCENE_GLOB ")\"'\n"
          "}\n\n"
          "_clpt \"$@\"\n", f);
}

int main(int argc, char **argv)
{
    const char *what = argc == 2 ? argv[1] : "";
    if (strcmp(what, "man") == 0) write_man(stdout);
    else if (strcmp(what, "bash") == 0) write_bash(stdout);
    else if (strcmp(what, "zsh") == 0) write_zsh(stdout);
    else {
        fprintf(stderr, "usage: clpt_docs man|bash|zsh\n");
        return 2;
    }
    if (fflush(stdout) != 0 || ferror(stdout)) {
        perror("clpt_docs: standard output");
        return 1;
    }
    return 0;
}
