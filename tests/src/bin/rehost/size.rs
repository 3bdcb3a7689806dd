//! The firmware's flash and RAM, read by binutils' `size -A` from the ELF as flashed, and the flash against its
//! budget: a quarter of the 256 KiB program area (sectors 0-5) is kept free for what comes next.

use std::path::Path;
use std::process::Command;

/// Most flash the firmware may take: the goal, 196,608 B, three quarters of the program area (the firmware takes
/// 194,420 B).
pub const FLASH_BUDGET: u64 = 196_608;

/// What the ELF takes of each memory (bytes).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Memory {
    /// Flash: the vector table, code, constants and the initial values of `.data`.
    pub flash: u64,
    /// RAM: `.data`, `.bss` and the uninitialised section.
    pub ram: u64,
}

/// The memory of `size -A` output; `None` when its table has no `.vector_table` or `.text` row (not a firmware ELF).
pub fn parse(size_a: &str) -> Option<Memory> {
    let mut memory = Memory { flash: 0, ram: 0 };
    let mut code = 0;
    for line in size_a.lines() {
        let mut columns = line.split_whitespace();
        let (Some(section), Some(Ok(bytes))) = (columns.next(), columns.next().map(str::parse::<u64>)) else {
            continue;
        };
        match section {
            ".vector_table" | ".text" => {
                code += 1;
                memory.flash += bytes;
            }
            ".rodata" => memory.flash += bytes,
            ".data" => {
                memory.flash += bytes;
                memory.ram += bytes;
            }
            ".bss" | ".uninit" => memory.ram += bytes,
            _ => {}
        }
    }
    (code == 2).then_some(memory)
}

/// The memory the ELF at `elf` takes.
pub fn measure(elf: &Path) -> Result<Memory, String> {
    let out = Command::new("size")
        .arg("-A")
        .arg(elf)
        .output()
        .map_err(|e| format!("size: {e} (apt-get install binutils)"))?;
    if !out.status.success() {
        return Err(format!("size -A {} failed", elf.display()));
    }
    parse(&String::from_utf8_lossy(&out.stdout))
        .ok_or_else(|| format!("size -A {}: no firmware sections", elf.display()))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// `size -A` on a firmware ELF, debug sections included.
    const REPORT: &str = "ringpod-firmware  :
section              size        addr
.vector_table         408   134217728
.text              173860   134218136
.rodata             16752   134391996
.data                 376   536870912
.gnu.sgstubs            0   134408752
.bss                43016   536871288
.uninit              1024   536914304
.defmt                198           0
.debug_info       1392960           0
Total             1628594
";

    #[test]
    fn flash_and_ram_are_the_sections_each_takes() {
        assert_eq!(
            parse(REPORT),
            Some(Memory {
                flash: 408 + 173_860 + 16_752 + 376,
                ram: 376 + 43_016 + 1_024,
            })
        );
    }

    #[test]
    fn a_report_without_code_is_not_a_firmware() {
        assert_eq!(parse(""), None);
        assert_eq!(parse(&REPORT.replace(".text", ".text2")), None);
        assert_eq!(parse("size: 'x': No such file"), None);
    }
}
