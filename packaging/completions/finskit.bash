# bash completion for fins, finsd and fins-bridge (finskit), installed as
# /usr/share/bash-completion/completions/fins, .../finsd and .../fins-bridge.
# CLI11 has no completion generator: the verbs and options are read from the program's
# own --help at each Tab (`fins --help`, `fins files --help`, `finsd ctl --help` ...), so
# the completion always matches the installed program, verb for verb.

# _finskit_help_words SECTION CMD...: the words of the "Subcommands:" or "Options:"
# section of `CMD... --help`. `finsd ctl` is parsed before CLI11 sees it: finsd's help
# names it in its last lines ("finsd ctl --socket PATH VERB ...").
_finskit_help_words() {
    local section=$1
    shift
    if [[ $section == Subcommands && ${#} -eq 1 && ${1##*/} == finsd ]]; then echo ctl; fi
    "$@" --help 2>/dev/null | awk -v section="$section" '
        /^[A-Za-z][A-Za-z ]*:$/ { in_section = ($0 == section ":"); next }
        !in_section { next }
        section == "Subcommands" && /^  [a-z]/ { print $1; next }
        section == "Options" && /^  -/ {
            n = split($1, names, ",")
            for (i = 1; i <= n; i++) {
                name = names[i]
                sub(/\{.*/, "", name)
                if (name ~ /^--?[A-Za-z]/) print name
            }
        }'
}

_finskit_complete() {
    local cur=${COMP_WORDS[COMP_CWORD]} prev=""
    ((COMP_CWORD > 0)) && prev=${COMP_WORDS[COMP_CWORD - 1]}
    COMPREPLY=()
    case $prev in
        --config | --data-dir | --control | --socket | --serial | --file | -o | --output)
            mapfile -t COMPREPLY < <(compgen -f -- "$cur")
            return
            ;;
        --log-level)
            mapfile -t COMPREPLY < <(compgen -W "trace debug info warn error off" -- "$cur")
            return
            ;;
    esac
    # The command chain so far: the program and each word naming a subcommand of it.
    local chain=("${COMP_WORDS[0]}") i verbs
    for ((i = 1; i < COMP_CWORD; i++)); do
        verbs=$(_finskit_help_words Subcommands "${chain[@]}")
        if grep -qxF -- "${COMP_WORDS[i]}" <<<"$verbs"; then chain+=("${COMP_WORDS[i]}"); fi
    done
    local words
    if [[ $cur == -* ]]; then
        words=$(_finskit_help_words Options "${chain[@]}")
    else
        words=$(_finskit_help_words Subcommands "${chain[@]}")
    fi
    mapfile -t COMPREPLY < <(compgen -W "$words" -- "$cur")
}
complete -F _finskit_complete fins finsd fins-bridge
