// The public header compiles as C++ with every warning an error.
#include <amscr.h>

int main()
{
    amscr_params *p = nullptr;
    if (amscr_params_new(&p) != AMSCR_OK)
        return 1;
    amscr_params_free(p);
    return amscr_version_number() == AMSCR_VERSION_NUMBER ? 0 : 1;
}
