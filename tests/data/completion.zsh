# completion.zsh DIR — tests/test_install.c's zsh part: loads _clpt from DIR into an
# interactive zsh on a pseudo-terminal (zsh/zpty), as a user's shell would, and types
# at it. Prints what the shell showed; the test looks for the lines it expects:
#   a list for "clpt --sp<TAB>" (--split and --spp, with their descriptions), and
#   "RESULT: clpt --interactive" once "clpt --interact<TAB>" was completed.
# The words the shell echoes are split by '' so that only its output matches a pattern.
zmodload zsh/zpty || exit 3
zpty z 'zsh -f -i'
zpty -w z "PS1=''; PROMPT_EOL_MARK=''; bindkey -e; fpath=(${1:A} \$fpath); autoload -Uz compinit; compinit -u -D; print READ''Y"
zpty -r z out '*READY*' || exit 4
# the list is drawn only when no typed keys wait: wait for it before typing on
zpty -w -n z $'clpt --sp\t'
zpty -r z listing '*--spp*samples per pixel*' || exit 5
print -r -- "$listing"
zpty -w z $'\C-uprint LIST\'\'ED'
zpty -r z out '*LISTED*' || exit 5
zpty -w -n z $'clpt --interact\t'
zpty -w z $'\C-aprint -r -- RES\'\'ULT: '
zpty -r z result '*RESULT:*clpt --interactive*' || exit 6
print -r -- "$result"
zpty -d z
