/* c_numeric.c — numbers read and written in the "C" locale whatever locale the program chose.
 *
 * A program that calls setlocale(LC_ALL, "") (GUI toolkits do, and Python's locale module) gives
 * strtod and printf its decimal point: a German or French one is ','. Point lists are read and
 * written with '.', so the text calls switch the calling thread (uselocale, POSIX 2008) to the
 * "C" numeric rules for the time of the call and back; the process's locale is never touched. */
#include "internal.h"

amscr_status amscr__c_numeric_enter(amscr__c_numeric *s)
{
    s->c = newlocale(LC_NUMERIC_MASK, "C", (locale_t)0);
    if (s->c == (locale_t)0)
        return amscr__fail(AMSCR_E_NOMEM, "out of memory (the \"C\" numeric locale)");
    s->prev = uselocale(s->c);
    return AMSCR_OK;
}

void amscr__c_numeric_leave(amscr__c_numeric *s)
{
    uselocale(s->prev);
    freelocale(s->c);
}
