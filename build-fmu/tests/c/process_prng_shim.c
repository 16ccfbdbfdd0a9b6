/* Rust's standard library (1.78 and later) imports ProcessPrng from bcryptprimitives.dll,
 * which Windows 10 has and wine 8 lacks: this DLL, put next to a Windows program run under
 * wine, forwards it to BCryptGenRandom (tests only; shipped nowhere). */
#include <windows.h>
#include <bcrypt.h>
__declspec(dllexport) BOOL WINAPI ProcessPrng(PBYTE data, SIZE_T len) {
    return BCryptGenRandom(NULL, data, (ULONG)len, BCRYPT_USE_SYSTEM_PREFERRED_RNG) == 0;
}
