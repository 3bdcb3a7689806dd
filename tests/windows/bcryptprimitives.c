/* Test-only stand-in for Windows' bcryptprimitives.dll, for running ringpod's Windows builds under Wine 8.

   Rust's standard library (1.78 and later) takes its random bytes (HashMap seeds) from ProcessPrng, which Windows 10
   and later export from bcryptprimitives.dll. Wine 8 (Debian 12's) has the DLL without that export, so every Rust
   program fails to load there. Placed beside the test executables, this DLL provides ProcessPrng through
   RtlGenRandom (advapi32's SystemFunction036), which Wine has. It is never shipped: Windows has the real one. */
#include <windows.h>

BOOLEAN WINAPI SystemFunction036(PVOID buffer, ULONG length);

__declspec(dllexport) BOOL WINAPI ProcessPrng(PBYTE data, SIZE_T length)
{
    while (length > 0) {
        ULONG chunk = length > 0x10000000 ? 0x10000000 : (ULONG)length;
        if (!SystemFunction036(data, chunk)) {
            return FALSE;
        }
        data += chunk;
        length -= chunk;
    }
    return TRUE;
}
