/* The public header compiles as strict C99 with every warning an error. */
#include <amscr.h>

int main(void)
{
    return amscr_version_number() == AMSCR_VERSION_NUMBER ? 0 : 1;
}
