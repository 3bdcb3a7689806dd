"""RCC on Qiling's STM32F4xxRcc, with the reset flags and ready bits this harness relies on (RM0383 section 6).

Qiling's model sets a ready bit only when the emulator steps every peripheral (which this harness's scheduler
does not do), and CSR.RMVF does not clear the reset flags.
"""

from qiling.hw.misc.stm32f4xx_rcc import STM32F4xxRcc

CR, PLLCFGR, CFGR, CSR = 0x00, 0x04, 0x08, 0x74
# RM0383 6.3, RCC_CSR reset flags
RMVF = 1 << 24
BORRSTF, PINRSTF, PORRSTF, SFTRSTF, IWDGRSTF, WWDGRSTF, LPWRRSTF = (1 << n for n in range(25, 32))
POWER_ON = BORRSTF | PINRSTF | PORRSTF  # RM0383 6.3, RCC_CSR after a power-on reset (0x0E00_0000)
HSE_HZ = 25_000_000  # the Black Pill's crystal
HSI_HZ = 16_000_000


class Rcc(STM32F4xxRcc):
    def read(self, offset, size):
        # RM0383 6.3.1 RCC_CR: HSIRDY/HSERDY/PLLRDY follow their ON bits (the oscillators start at once here);
        # 6.3.3 RCC_CFGR: SWS follows SW
        self.step()
        return super().read(offset, size)

    def write(self, offset, size, value):
        if offset == CSR and value & RMVF:
            # RM0383 6.3, RCC_CSR: writing RMVF clears every reset flag
            value &= ~(RMVF | 0xFE00_0000)
        super().write(offset, size, value)

    def set_reset_flags(self, flags):
        self.instance.CSR = (self.instance.CSR & 0x00FF_FFFF) | flags

    def sysclk_hz(self):
        """SYSCLK from SWS and the PLL dividers (RM0383 6.3.2 RCC_PLLCFGR, 6.3.3 RCC_CFGR)."""
        sws = (self.instance.CFGR >> 2) & 3
        if sws == 0:
            return HSI_HZ
        if sws == 1:
            return HSE_HZ
        p = self.instance.PLLCFGR
        m, n, pdiv = p & 0x3F, (p >> 6) & 0x1FF, 2 * (((p >> 16) & 3) + 1)
        src = HSE_HZ if p & (1 << 22) else HSI_HZ
        return src // m * n // pdiv
